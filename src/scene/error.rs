//! Scene errors and their file locations.
//!
//! Syntax errors, unknown keys and wrong types come from the toml deserializer with a
//! byte span; we turn the span into `line:column` (1-based, columns in characters) and
//! make the message name the key where toml's does not. Semantic errors carry the
//! location of the offending value when it still is the one read from the file.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// A 1-based line and column (in characters) in a scene file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Location {
    pub line: usize,
    pub column: usize,
}

impl Location {
    /// The location of byte `offset` in `text` (clamped to the text, moved back to a
    /// character boundary).
    pub fn from_offset(text: &str, offset: usize) -> Location {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &text[..offset];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Location {
            line: before.matches('\n').count() + 1,
            column: before[line_start..].chars().count() + 1,
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// Why a scene could not be loaded or is not valid. The messages start with
/// `path:line:column:` when the place in the file is known.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read (missing, unreadable, not UTF-8).
    #[error("cannot read scene file {}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The TOML is malformed, or a key is unknown, missing or of the wrong type.
    #[error("{}", with_place(path, location, message))]
    Syntax {
        path: PathBuf,
        location: Option<Location>,
        message: String,
    },
    /// A value is out of range or inconsistent with another. `field` is the dotted key
    /// (`image.width`, `object[2].alpha`; objects count from 0); `location` is `None`
    /// when the value was not read from the file (a default, or set after loading, e.g.
    /// by a command-line override).
    #[error("{}", with_place(path, location, message))]
    Invalid {
        path: PathBuf,
        location: Option<Location>,
        field: String,
        message: String,
    },
}

impl SceneError {
    /// The location in the scene file, when known.
    pub fn location(&self) -> Option<Location> {
        match self {
            SceneError::Read { .. } => None,
            SceneError::Syntax { location, .. } | SceneError::Invalid { location, .. } => *location,
        }
    }
}

fn with_place(path: &Path, location: &Option<Location>, message: &str) -> String {
    match (path.as_os_str().is_empty(), location) {
        (true, _) => message.to_string(),
        (false, Some(l)) => format!("{}:{l}: {message}", path.display()),
        (false, None) => format!("{}: {message}", path.display()),
    }
}

/// Converts a toml deserialization error into a [`SceneError::Syntax`] with a location
/// and a message that names the offending key.
pub(super) fn from_toml(path: &Path, text: &str, err: &toml::de::Error) -> SceneError {
    let raw = err.message().trim_end();
    let Some(span) = err.span() else {
        return SceneError::Syntax {
            path: path.to_path_buf(),
            location: None,
            message: plain_types(raw),
        };
    };
    let span = clamp_span(text, span);
    let (span, message) = explain(text, span, raw);
    SceneError::Syntax {
        path: path.to_path_buf(),
        location: Some(Location::from_offset(text, span.start)),
        message: plain_types(&message),
    }
}

fn clamp_span(text: &str, span: Range<usize>) -> Range<usize> {
    let end = span.end.min(text.len());
    span.start.min(end)..end
}

/// Points the span at the key the message is about and names the key in the message.
fn explain(text: &str, span: Range<usize>, message: &str) -> (Range<usize>, String) {
    let spanned = text.get(span.clone()).unwrap_or("");
    if let Some(key) = backquoted_after(message, "unknown field ") {
        // Inside internally tagged enums (the generator) toml reports the whole table;
        // find the key itself.
        if !spanned.starts_with(key) {
            let limit = if spanned.starts_with('[') {
                next_header(text, span.end)
            } else {
                span.end
            };
            if let Some(at) = find_key(text, span.start, limit, key) {
                return (at..at + key.len(), message.to_string());
            }
        }
        return (span, message.to_string());
    }
    if message == "duplicate key" && is_bare_key(spanned) {
        return (span, format!("duplicate key `{spanned}`"));
    }
    if let Some(field) = backquoted_after(message, "missing field ") {
        if field == "camera" && span.start == 0 && span.is_empty() {
            return (
                span,
                "missing [camera] table (it needs at least `origin` and `target`)".to_string(),
            );
        }
        if spanned.starts_with('[') && !spanned.contains('\n') {
            return (span, format!("{message} in {spanned}"));
        }
        if let Some(key) = key_before(text, span.start) {
            return (span, format!("{message} in `{key}`"));
        }
        return (span, message.to_string());
    }
    // A wrong value inside an internally tagged table (the generator) is reported at the
    // whole table; find the value the message quotes.
    if spanned.starts_with(['{', '[']) {
        let limit = if spanned.starts_with('[') {
            next_header(text, span.end)
        } else {
            span.end
        };
        let at = quoted_value(message).and_then(|v| find_value(text, span.start, limit, &v));
        if let Some(at) = at
            && let Some(key) = key_before(text, at)
        {
            return (at..at, format!("`{key}`: {message}"));
        }
    }
    if let Some(key) = key_before(text, span.start) {
        return (span, format!("`{key}`: {message}"));
    }
    (span, message.to_string())
}

/// The value serde quotes in "invalid type/value" messages, as it would be written in
/// TOML: `integer `-3``, `floating point `2.5``, `boolean `true``, `string "x"`.
fn quoted_value(message: &str) -> Option<String> {
    for prefix in ["integer ", "floating point ", "boolean "] {
        if let Some(i) = message.find(&format!(": {prefix}`")) {
            let rest = &message[i + prefix.len() + 3..];
            return rest.split_once('`').map(|(v, _)| v.to_string());
        }
    }
    let i = message.find(": string \"")?;
    let rest = &message[i + ": string ".len()..];
    let end = rest[1..].find('"')?;
    Some(rest[..end + 2].to_string())
}

/// The offset of the only value in `text[from..limit]` written exactly as `value` after
/// `key =`; `None` when there is no such value or more than one.
fn find_value(text: &str, from: usize, limit: usize, value: &str) -> Option<usize> {
    let region = text.get(from..limit)?;
    let mut found = region
        .match_indices(value)
        .map(|(i, _)| from + i)
        .filter(|&at| {
            let after = &text[at + value.len()..];
            let ends =
                after.is_empty() || after.starts_with([' ', '\t', ',', '}', '\n', '\r', '#']);
            ends && key_before(text, at).is_some()
        });
    let first = found.next()?;
    found.next().is_none().then_some(first)
}

/// `Some("x")` when `message` starts with `prefix` followed by `` `x` ``.
fn backquoted_after<'m>(message: &'m str, prefix: &str) -> Option<&'m str> {
    let rest = message.strip_prefix(prefix)?.strip_prefix('`')?;
    rest.split_once('`').map(|(key, _)| key)
}

fn is_key_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '-'
}

fn is_bare_key(s: &str) -> bool {
    !s.is_empty() && s.chars().all(is_key_char)
}

/// Offset of the next line that starts a table header (`[`), or the end of the text.
fn next_header(text: &str, from: usize) -> usize {
    let mut at = from;
    for line in text[from..].split_inclusive('\n') {
        if at > from && line.trim_start().starts_with('[') {
            return at;
        }
        at += line.len();
    }
    text.len()
}

/// Finds `key` written as a bare key (`key = ...`) in `text[from..limit]`: preceded, on
/// its line, only by blanks, `{` or `,`, and followed by `=`.
fn find_key(text: &str, from: usize, limit: usize, key: &str) -> Option<usize> {
    let region = text.get(from..limit)?;
    region
        .match_indices(key)
        .map(|(i, _)| from + i)
        .find(|&at| {
            let before = text[..at].trim_end_matches([' ', '\t']);
            let after = text[at + key.len()..].trim_start_matches([' ', '\t']);
            let starts = before.is_empty() || before.ends_with(['\n', '{', ',']);
            starts && after.starts_with('=')
        })
}

/// The bare key written just before byte `offset` on its line (`key = <offset>`).
fn key_before(text: &str, offset: usize) -> Option<&str> {
    let before = text.get(..offset)?;
    let line = &before[before.rfind('\n').map_or(0, |i| i + 1)..];
    let line = line.trim_end().strip_suffix('=')?.trim_end();
    let start = line
        .char_indices()
        .rev()
        .take_while(|&(_, c)| is_key_char(c) || c == '.')
        .last()
        .map(|(i, _)| i)?;
    let key = &line[start..];
    (!key.is_empty()).then_some(key)
}

/// Replaces Rust type names in serde messages by words a scene author knows.
fn plain_types(message: &str) -> String {
    let mut m = message.to_string();
    for (rust, plain) in [
        ("expected f64", "expected a number"),
        ("expected f32", "expected a number"),
        ("expected i64", "expected an integer"),
        ("expected u32", "expected a non-negative integer"),
        ("expected usize", "expected a non-negative integer"),
        ("expected a sequence", "expected an array"),
        ("expected a map", "expected a table"),
        ("wanted string or table", "expected a name in quotes"),
    ] {
        m = m.replace(rust, plain);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locations() {
        let t = "ab\ncdé f\n\nx";
        assert_eq!(Location::from_offset(t, 0), Location { line: 1, column: 1 });
        assert_eq!(Location::from_offset(t, 3), Location { line: 2, column: 1 });
        // 'é' is two bytes; the space after it is the 4th character.
        assert_eq!(Location::from_offset(t, 7), Location { line: 2, column: 4 });
        // Inside a multi-byte character: back to its start.
        assert_eq!(Location::from_offset(t, 6), Location { line: 2, column: 3 });
        assert_eq!(
            Location::from_offset(t, 11),
            Location { line: 4, column: 1 }
        );
        assert_eq!(
            Location::from_offset(t, 999),
            Location { line: 4, column: 2 }
        );
    }

    #[test]
    fn key_helpers() {
        let t = "a = 1\n[object.generator]\nkind = 'torus'\n  bogus= 3\n[x]\nbogus = 1\n";
        let header = t.find("[object").unwrap();
        let limit = next_header(t, header + 18);
        assert_eq!(&t[limit..limit + 3], "[x]");
        let at = find_key(t, header, limit, "bogus").unwrap();
        assert_eq!(
            Location::from_offset(t, at),
            Location { line: 4, column: 3 }
        );
        let t = "g = { kind = 'torus', bogus = 3 }";
        assert_eq!(find_key(t, 4, t.len(), "bogus"), Some(22));
        assert_eq!(find_key(t, 4, t.len(), "torus"), None);
        assert_eq!(key_before("  width = 960.0", 10), Some("width"));
        assert_eq!(key_before("t = { scale = 'x' }", 14), Some("scale"));
        assert_eq!(key_before("[1, 2]", 1), None);
        let t = "g = { kind = 'torus', a = -3, b = -30, c = \"x\" }";
        assert_eq!(find_value(t, 4, t.len(), "-3"), t.find("-3,"));
        assert_eq!(find_value(t, 4, t.len(), "\"x\""), t.find("\"x\""));
        assert_eq!(find_value(t, 4, t.len(), "7"), None);
        let m = "invalid value: integer `-3`, expected usize";
        assert_eq!(quoted_value(m).as_deref(), Some("-3"));
        let m = "invalid type: string \"x y\", expected f32";
        assert_eq!(quoted_value(m).as_deref(), Some("\"x y\""));
        let m = "invalid type: floating point `2.5`, expected usize";
        assert_eq!(quoted_value(m).as_deref(), Some("2.5"));
    }
}
