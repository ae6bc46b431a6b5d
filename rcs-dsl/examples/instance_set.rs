//! Writes the benchmark's instance sets (`benches/common/instance_set.rs`)
//! to disk, for `rcsc` and a build.rs crate to be timed on:
//! `cargo run -p rcs-dsl --example instance_set -- DIR [N]` writes
//! `DIR/types/axes.rcs` (N instances of one type) and
//! `DIR/copies/axes.rcs` (the same N axes written out). Default N: 100.

#[path = "../benches/common/instance_set.rs"]
mod instance_set;

fn main() -> std::io::Result<()> {
    let mut args = std::env::args().skip(1);
    let dir = std::path::PathBuf::from(args.next().unwrap_or_else(|| "instance-set".into()));
    let n: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100);
    for (sub, text) in [
        ("types", instance_set::instances(n)),
        ("copies", instance_set::copies(n)),
    ] {
        std::fs::create_dir_all(dir.join(sub))?;
        std::fs::write(dir.join(sub).join("axes.rcs"), text)?;
    }
    Ok(())
}
