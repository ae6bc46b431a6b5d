//! Generate Figure 13's controller (`plans/figure13`) into
//! `$OUT_DIR/rcs/rust/figure13.rs`, as a user's build.rs would.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    rcs_codegen::Config::new().compile("../../plans/figure13")?;
    Ok(())
}
