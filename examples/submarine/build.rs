//! Generate the submarine controllers (`plans/submarine`) into
//! `$OUT_DIR/rcs/rust/submarine.rs`, as a user's build.rs would.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // serde derives on the buffer types: `--foxglove` serves the `ship`,
    // `turbine` and `drive` buffers live as JSON (src/foxglove.rs).
    rcs_codegen::Config::new()
        .serde(rcs_codegen::SerdeDerives::Always)
        .compile("../../plans/submarine")?;
    Ok(())
}
