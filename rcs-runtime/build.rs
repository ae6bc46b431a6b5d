//! Tells the crates that depend on `rcs-runtime` where its source is.
//!
//! `rcsc` ships this crate's source inside its binary (its `build.rs`
//! embeds every file of `src/` for `rcsc test --backend compiled`). In this
//! repository the folder is beside rcsc's; installed from crates.io it is
//! wherever cargo unpacked `rcs-runtime`. Cargo passes a `links` crate's
//! `cargo::metadata` to its direct dependents' build scripts, as
//! `DEP_RCS_RUNTIME_ROOT`, so rcsc finds the source in both cases without a
//! relative path that only holds in a checkout.

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    let root = std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo");
    println!("cargo::metadata=root={root}");
}
