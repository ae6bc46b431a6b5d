//! Compiles the committed, generated C parser (`src/parser.c`), so that
//! neither users nor CI need the tree-sitter CLI or Node.

fn main() {
    let src_dir = std::path::Path::new("src");
    let parser = src_dir.join("parser.c");

    let mut c_config = cc::Build::new();
    c_config
        .std("c11")
        .include(src_dir)
        // Generated parsers trip these; the code is not ours to change.
        .flag_if_supported("-Wno-unused-parameter")
        .flag_if_supported("-Wno-unused-but-set-variable")
        .flag_if_supported("-Wno-trigraphs");
    c_config.file(&parser);
    println!("cargo:rerun-if-changed={}", parser.display());

    // An external scanner, if the grammar ever gets one.
    let scanner = src_dir.join("scanner.c");
    if scanner.exists() {
        c_config.file(&scanner);
        println!("cargo:rerun-if-changed={}", scanner.display());
    }

    c_config.compile("tree-sitter-rcs");
}
