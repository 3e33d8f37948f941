//! A run file: a [`RunDescription`] in TOML, or in JSON when the file's name ends in
//! `.json`. Errors name the file, the line and the key, user text escaped
//! ([`crate::text::Clipped`]), as the spacecraft file's do. Relative file names in it
//! (`spacecraft`, `nominal`, `prior`) are relative to the run file's folder.

use super::{InertiaInput, RunDescription};
use crate::text::Clipped;
use std::format;
use std::path::Path;
use std::string::{String, ToString};

/// A run file that cannot be used: the file, the line (where the problem has one), the
/// key (where there is one) and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{}{}{message}", .line.map_or_else(String::new, |l| format!("{l}:")), .key.as_ref().map_or_else(String::new, |k| format!(" `{}`:", Clipped::new(k))))]
pub struct RunFileError {
    /// The file (as the caller named it).
    pub file: String,
    /// 1-based line, where the problem has one.
    pub line: Option<usize>,
    /// The key at fault, where there is one.
    pub key: Option<String>,
    /// What is wrong (one line, control characters escaped).
    pub message: String,
}

/// The most a run file may hold, bytes.
const LIMIT: u64 = 1 << 20;

impl RunDescription {
    /// Read a run file (TOML, or JSON for a name ending in `.json`).
    pub fn load(path: &Path) -> Result<Self, RunFileError> {
        use std::io::Read;
        let file = path.display().to_string();
        let fail = |message: String| RunFileError {
            file: file.clone(),
            line: None,
            key: None,
            message: format!(" {}", Clipped::with_limit(&message, 300)),
        };
        let mut text = String::new();
        std::fs::File::open(path)
            .and_then(|f| f.take(LIMIT + 1).read_to_string(&mut text))
            .map_err(|e| fail(e.to_string()))?;
        if text.len() as u64 > LIMIT {
            return Err(fail(format!("longer than {LIMIT} bytes: not a run file")));
        }
        let json = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        let mut d = Self::parse(&text, &file, json)?;
        if let Some(dir) = path.parent() {
            d.rebase(dir);
        }
        Ok(d)
    }

    /// A run file's text (`json`: JSON, else TOML); `file` names it in messages.
    pub(crate) fn parse(text: &str, file: &str, json: bool) -> Result<Self, RunFileError> {
        let line_of = |offset: usize| 1 + text[..offset.min(text.len())].matches('\n').count();
        let err = |line: Option<usize>, message: &str| {
            let message = plain(message);
            // The key of the line the error points at (`key = …` or `"key": …`).
            let key = line.and_then(|l| {
                let (k, _) = text
                    .lines()
                    .nth(l - 1)?
                    .split_once(if json { ':' } else { '=' })?;
                let k = k
                    .trim()
                    .trim_matches(|c| c == '"' || c == '{' || c == ',')
                    .trim();
                (!k.is_empty() && !k.starts_with('#')).then(|| k.to_string())
            });
            RunFileError {
                file: file.to_string(),
                line,
                key,
                message: format!(" {}", Clipped::with_limit(&message, 300)),
            }
        };
        if json {
            serde_json::from_str(text).map_err(|e| {
                // serde_json appends " at line L column C": the line is given apart.
                let m = e.to_string();
                let m = m.rsplit_once(" at line ").map_or(m.as_str(), |(m, _)| m);
                err((e.line() > 0).then_some(e.line()), m)
            })
        } else {
            toml::from_str(text).map_err(|e| {
                // toml's message spans several lines (it quotes the file): keep its first.
                let m = e.message().lines().next().unwrap_or("").to_string();
                err(e.span().map(|s| line_of(s.start)), &m)
            })
        }
    }

    /// Relative file names made relative to `dir` (the run file's folder).
    fn rebase(&mut self, dir: &Path) {
        let on = |p: &mut std::path::PathBuf| {
            if p.is_relative() {
                *p = dir.join(&*p);
            }
        };
        if let Some(p) = &mut self.spacecraft {
            on(p);
        }
        for i in [&mut self.nominal, &mut self.prior].into_iter().flatten() {
            if let InertiaInput::File(p) = i {
                on(p);
            }
        }
    }
}

/// A deserialiser's message in a user's words: an unknown key without the list of every
/// key, serde's type names as what they are.
fn plain(message: &str) -> String {
    let m = match message.split_once(", expected one of `") {
        Some((head, _)) if head.starts_with("unknown field") => {
            format!("{head} (the keys are `inertia estimate`'s long options in snake case)")
        }
        _ => message.to_string(),
    };
    m.replace("unknown field", "unknown key")
        .replace("expected f64", "expected a number")
        .replace("expected usize", "expected an integer >= 0")
        .replace("expected a boolean", "expected true or false")
}
