//! Fenced code blocks of a markdown file, for the tests that check the
//! documentation as code (`docs.rs`, and the README walk-through).

#![allow(dead_code)] // each test binary uses what it needs

use std::collections::BTreeSet;

/// One fenced block: its info string words, its text and its first line.
pub struct Block {
    pub lang: String,
    pub attrs: Vec<String>,
    pub text: String,
    pub line: usize,
}

pub fn blocks(markdown: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut current: Option<Block> = None;
    for (i, line) in markdown.lines().enumerate() {
        let trimmed = line.trim_start();
        match current.take() {
            None => {
                if let Some(info) = trimmed.strip_prefix("```") {
                    let mut words = info.split_whitespace().map(str::to_string);
                    current = Some(Block {
                        lang: words.next().unwrap_or_default(),
                        attrs: words.collect(),
                        text: String::new(),
                        line: i + 2,
                    });
                }
            }
            Some(mut b) => {
                if trimmed.starts_with("```") {
                    out.push(b);
                } else {
                    b.text.push_str(line);
                    b.text.push('\n');
                    current = Some(b);
                }
            }
        }
    }
    assert!(current.is_none(), "an unclosed ``` block");
    out
}

impl Block {
    /// `expect=a,b` (also `expect=a, b` split over words), if given.
    pub fn expected(&self) -> Option<BTreeSet<String>> {
        let joined = self.attrs.join(" ");
        let rest = joined.split_once("expect=")?.1;
        Some(
            rest.split(',')
                .map(|s| s.trim().to_string())
                .filter(|s| !s.is_empty())
                .collect(),
        )
    }

    pub fn is_fragment(&self) -> bool {
        self.attrs.iter().any(|a| a == "fragment")
    }
}
