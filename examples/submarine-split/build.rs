//! Generate the split submarine (`plans/`, whose manifest places SM and PR
//! in process `helm` and TB in process `engine`) into `$OUT_DIR/rcs/`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    rcs_codegen::Config::new().compile("plans")?;
    Ok(())
}
