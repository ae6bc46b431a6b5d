//! `rcsfmt.toml`: the formatter's settings for the files of a folder and
//! the folders below it. The nearest file in a `.rcs` file's folder or
//! above it applies; without one, the defaults.
//!
//! ```toml
//! # rcsfmt.toml
//! max_width = 100   # rows and blocks longer than this are broken
//! ```
//!
//! Only this one key exists today; an unknown key is an error, so a typo
//! is not silently ignored. The file is read with a tiny parser of
//! `key = integer` lines (comments with `#`), which is all it can hold.

use std::path::{Path, PathBuf};

/// The name of the settings file.
pub const FILE_NAME: &str = "rcsfmt.toml";

/// The layout's settings.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FmtOptions {
    /// The width rows and one-line blocks must fit, in characters.
    pub max_width: usize,
}

impl Default for FmtOptions {
    fn default() -> Self {
        FmtOptions { max_width: 100 }
    }
}

/// The settings for the file `path`: from the nearest `rcsfmt.toml` in
/// its folder or above, with the file's path, or the defaults. `Err`
/// names the settings file and what is wrong with it.
pub fn options_for(path: &Path) -> Result<(FmtOptions, Option<PathBuf>), String> {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut dir = absolute.parent();
    while let Some(d) = dir {
        let candidate = d.join(FILE_NAME);
        if candidate.is_file() {
            let text = std::fs::read_to_string(&candidate)
                .map_err(|e| format!("cannot read {}: {e}", candidate.display()))?;
            let options = parse(&text).map_err(|e| format!("{}: {e}", candidate.display()))?;
            return Ok((options, Some(candidate)));
        }
        dir = d.parent();
    }
    Ok((FmtOptions::default(), None))
}

/// The settings a `rcsfmt.toml` text gives.
pub fn parse(text: &str) -> Result<FmtOptions, String> {
    let mut options = FmtOptions::default();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let Some((key, value)) = line.split_once('=') else {
            return Err(format!("line {}: expected `key = value`", n + 1));
        };
        match key.trim() {
            "max_width" => {
                let width: usize = value
                    .trim()
                    .parse()
                    .map_err(|_| format!("line {}: `max_width` must be a whole number", n + 1))?;
                if !(20..=1000).contains(&width) {
                    return Err(format!(
                        "line {}: `max_width` must be between 20 and 1000",
                        n + 1
                    ));
                }
                options.max_width = width;
            }
            other => {
                return Err(format!(
                    "line {}: unknown setting `{other}` (the settings are: max_width)",
                    n + 1
                ))
            }
        }
    }
    Ok(options)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_are_read_and_typos_refused() {
        assert_eq!(
            parse("# c\nmax_width = 80 # narrow\n").unwrap().max_width,
            80
        );
        assert_eq!(parse("").unwrap(), FmtOptions::default());
        assert!(parse("max_widht = 80")
            .unwrap_err()
            .contains("unknown setting `max_widht`"));
        assert!(parse("max_width = wide").is_err());
        assert!(parse("max_width = 5").is_err());
    }
}
