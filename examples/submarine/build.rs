//! Generate the submarine controllers (`plans/submarine`) into
//! `$OUT_DIR/rcs/rust/submarine.rs`, as a user's build.rs would.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    rcs_codegen::Config::new().compile("../../plans/submarine")?;
    Ok(())
}
