//! Strict PLY checks that `ply-rs-bw` leaves out (issue 10, defect 6).
//!
//! `ply-rs-bw` keeps the header's elements and properties in maps, so a repeated name
//! silently replaces the first; it accepts any `format` version and extra values at the
//! end of an ASCII element line, and stops reading after the last declared element. The
//! PLY format (Turk's specification, as in Paul Bourke's "PLY - Polygon File Format")
//! defines a file as the header followed by exactly the declared elements, each ASCII
//! element on its own line, with `format <ascii|binary_little_endian|binary_big_endian>
//! 1.0`. So we reject, naming the file and the 1-based line:
//! - a `format` line that is not exactly that (other versions, extra words, a second
//!   `format` line);
//! - two elements with the same name, two properties with the same name in one element;
//! - an ASCII element line with more values than its properties declare (fewer values,
//!   or malformed ones, are left to `ply-rs-bw`, which reports them);
//! - data after the last element. Trailing whitespace (a final newline, blank lines) is
//!   accepted, as writers commonly end a file with a newline; any other byte is an
//!   error, because the specification has no place for it and it usually means the
//!   header's counts or types do not match the data.

use super::MeshError;
use std::path::Path;

/// What the checks need from the header.
pub(super) struct HeaderInfo {
    /// Number of header lines, `ply` to `end_header` inclusive.
    pub lines: usize,
    /// Byte offset just after the `end_header` line.
    pub end: usize,
    pub ascii: bool,
    /// Elements in file order.
    pub elements: Vec<ElementInfo>,
}

pub(super) struct ElementInfo {
    pub name: String,
    pub count: u64,
    /// Property names and whether each is a list.
    pub properties: Vec<(String, bool)>,
}

/// Scans the header for the problems above. `Ok(None)` when the header is incomplete
/// or has lines this scan does not know (no `end_header`, unknown keywords): those are
/// left to `ply-rs-bw`, whose message names the line.
pub(super) fn check_header(bytes: &[u8], path: &Path) -> Result<Option<HeaderInfo>, MeshError> {
    let err = |line: usize, message: String| MeshError::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut info = HeaderInfo {
        lines: 0,
        end: 0,
        ascii: false,
        elements: Vec::new(),
    };
    let mut format_line = None;
    let mut offset = 0;
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = i + 1;
        offset += raw.len() + 1;
        let Ok(text) = std::str::from_utf8(raw) else {
            return Ok(None);
        };
        let tokens: Vec<&str> = text.split_whitespace().collect();
        match tokens.first().copied() {
            Some("format") => {
                if let Some(first) = format_line {
                    return Err(err(
                        line,
                        format!("a second 'format' line (the first is line {first})"),
                    ));
                }
                format_line = Some(line);
                match tokens.as_slice() {
                    ["format", enc, "1.0"]
                        if ["ascii", "binary_little_endian", "binary_big_endian"].contains(enc) =>
                    {
                        info.ascii = *enc == "ascii";
                    }
                    _ => {
                        return Err(err(
                            line,
                            format!(
                                "bad format line '{}': expected 'format ascii 1.0', 'format \
                                 binary_little_endian 1.0' or 'format binary_big_endian 1.0'",
                                text.trim()
                            ),
                        ));
                    }
                }
            }
            Some("element") => {
                let (Some(name), Some(count)) = (tokens.get(1), tokens.get(2)) else {
                    return Ok(None);
                };
                let Ok(count) = count.parse::<u64>() else {
                    return Ok(None);
                };
                if info.elements.iter().any(|e| e.name == *name) {
                    return Err(err(
                        line,
                        format!("element '{name}' is declared twice; element names must be unique"),
                    ));
                }
                info.elements.push(ElementInfo {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            Some("property") => {
                let (is_list, name) = match tokens.as_slice() {
                    ["property", "list", _, _, name] => (true, *name),
                    ["property", _, name] => (false, *name),
                    _ => return Ok(None),
                };
                let Some(element) = info.elements.last_mut() else {
                    return Ok(None);
                };
                if element.properties.iter().any(|(n, _)| n == name) {
                    return Err(err(
                        line,
                        format!(
                            "element '{}' declares property '{name}' twice; property names \
                             must be unique within an element",
                            element.name
                        ),
                    ));
                }
                element.properties.push((name.to_string(), is_list));
            }
            Some("end_header") => {
                info.lines = line;
                info.end = offset.min(bytes.len());
                return Ok(Some(info));
            }
            _ => {}
        }
    }
    Ok(None)
}

/// Checks that no ASCII element line holds more values than its properties declare.
/// Stops quietly at the first line it cannot follow (a missing line, a bad list count):
/// `ply-rs-bw` reports those.
pub(super) fn check_ascii_lines(
    bytes: &[u8],
    info: &HeaderInfo,
    path: &Path,
) -> Result<(), MeshError> {
    let mut lines = bytes[info.end..].split(|&b| b == b'\n');
    let mut line = info.lines;
    for element in &info.elements {
        for index in 0..element.count {
            let Some(raw) = lines.next() else {
                return Ok(());
            };
            line += 1;
            let Ok(text) = std::str::from_utf8(raw) else {
                return Ok(());
            };
            let tokens: Vec<&str> = text.split_whitespace().collect();
            let mut used = 0usize;
            for (_, is_list) in &element.properties {
                if *is_list {
                    let Some(n) = tokens.get(used).and_then(|t| t.parse::<usize>().ok()) else {
                        return Ok(());
                    };
                    used = used.saturating_add(1).saturating_add(n);
                } else {
                    used += 1;
                }
            }
            if tokens.len() > used {
                return Err(MeshError::Parse {
                    path: path.to_path_buf(),
                    line,
                    message: format!(
                        "element '{}' number {index} (counting from 0) has {} values, but its \
                         properties declare {used}",
                        element.name,
                        tokens.len()
                    ),
                });
            }
        }
    }
    Ok(())
}

/// Checks what is left after the last element: only whitespace is accepted. `rest` is
/// the unread tail of `bytes`; for ASCII the line is computed, for binary the byte
/// offset is given.
pub(super) fn check_trailing(
    bytes: &[u8],
    rest: &[u8],
    ascii: bool,
    path: &Path,
) -> Result<(), MeshError> {
    let Some(first) = rest.iter().position(|b| !b.is_ascii_whitespace()) else {
        return Ok(());
    };
    let at = bytes.len() - rest.len() + first;
    let what = format!(
        "{} byte(s) of data after the last element declared in the header; the header's \
         element counts or property types do not match the data",
        rest.len() - first
    );
    if ascii {
        Err(MeshError::Parse {
            path: path.to_path_buf(),
            line: 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count(),
            message: what,
        })
    } else {
        Err(MeshError::Format {
            path: path.to_path_buf(),
            message: format!("at byte {at}: {what}"),
        })
    }
}
