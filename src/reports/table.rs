//! One table type for every report: a readable fixed-width text form for the terminal,
//! CSV (full precision, one header line of column names) and JSON (an array of objects
//! keyed by column name). Column meanings and units are documented in `doc/reports.md`.

use crate::output::{Kind, Output, OutputError};
use std::fmt::Write as _;
use std::path::Path;

/// One cell of a table.
#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    Text(String),
    Int(i64),
    /// A number and the decimals shown in the text table (CSV and JSON keep all digits).
    Num(f64, usize),
    /// A number shown in scientific notation in the text table.
    Sci(f64),
    /// No value (written as an empty CSV field, `null` in JSON, `-` in text).
    Empty,
}

impl Cell {
    pub fn text(s: impl Into<String>) -> Cell {
        Cell::Text(s.into())
    }

    /// A number shown with `decimals` decimals; `None` becomes [`Cell::Empty`].
    pub fn num(v: impl Into<Option<f64>>, decimals: usize) -> Cell {
        match v.into() {
            Some(v) => Cell::Num(v, decimals),
            None => Cell::Empty,
        }
    }

    pub fn sci(v: impl Into<Option<f64>>) -> Cell {
        match v.into() {
            Some(v) => Cell::Sci(v),
            None => Cell::Empty,
        }
    }

    pub fn int(v: impl TryInto<i64>) -> Cell {
        v.try_into().map(Cell::Int).unwrap_or(Cell::Empty)
    }

    fn display(&self) -> String {
        match self {
            Cell::Text(s) => s.clone(),
            Cell::Int(i) => i.to_string(),
            Cell::Num(v, d) if v.is_finite() => format!("{v:.d$}"),
            Cell::Sci(v) if *v == 0.0 => "0".to_string(),
            Cell::Sci(v) if v.is_finite() => format!("{v:.2e}"),
            Cell::Num(v, _) | Cell::Sci(v) => v.to_string(),
            Cell::Empty => "-".to_string(),
        }
    }

    fn csv(&self) -> String {
        match self {
            Cell::Text(s) if s.contains([',', '"', '\n']) => {
                format!("\"{}\"", s.replace('"', "\"\""))
            }
            Cell::Text(s) => s.clone(),
            Cell::Int(i) => i.to_string(),
            Cell::Num(v, _) | Cell::Sci(v) => v.to_string(),
            Cell::Empty => String::new(),
        }
    }

    fn json(&self) -> serde_json::Value {
        match self {
            Cell::Text(s) => serde_json::Value::String(s.clone()),
            Cell::Int(i) => serde_json::Value::from(*i),
            Cell::Num(v, _) | Cell::Sci(v) => serde_json::Number::from_f64(*v)
                .map(serde_json::Value::Number)
                .unwrap_or(serde_json::Value::Null),
            Cell::Empty => serde_json::Value::Null,
        }
    }

    /// The number in the cell, if it holds one.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Cell::Int(i) => Some(*i as f64),
            Cell::Num(v, _) | Cell::Sci(v) => Some(*v),
            _ => None,
        }
    }
}

/// A table: column names (as used in CSV and JSON), short headers for the text form,
/// and rows of cells.
#[derive(Clone, Debug, Default)]
pub struct Table {
    /// `(csv name, text header)` per column.
    pub columns: Vec<(String, String)>,
    pub rows: Vec<Vec<Cell>>,
}

impl Table {
    /// A table with these `(csv name, text header)` columns.
    pub fn new(columns: &[(&str, &str)]) -> Table {
        Table {
            columns: columns
                .iter()
                .map(|(n, h)| (n.to_string(), h.to_string()))
                .collect(),
            rows: Vec::new(),
        }
    }

    pub fn push(&mut self, row: Vec<Cell>) {
        assert_eq!(row.len(), self.columns.len(), "row width");
        self.rows.push(row);
    }

    /// The index of the column with this CSV name.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|(n, _)| n == name)
    }

    /// A table of some of the columns (by CSV name, in the order given; unknown names
    /// are left out), for a narrower text form.
    pub fn select(&self, names: &[&str]) -> Table {
        let idx: Vec<usize> = names.iter().filter_map(|n| self.column(n)).collect();
        Table {
            columns: idx.iter().map(|&j| self.columns[j].clone()).collect(),
            rows: self
                .rows
                .iter()
                .map(|r| idx.iter().map(|&j| r[j].clone()).collect())
                .collect(),
        }
    }

    /// The rows for which `keep` holds.
    pub fn filter(&self, keep: impl Fn(&[Cell]) -> bool) -> Table {
        Table {
            columns: self.columns.clone(),
            rows: self.rows.iter().filter(|r| keep(r)).cloned().collect(),
        }
    }

    /// Text: columns two spaces apart, text left-aligned and numbers right-aligned.
    pub fn to_text(&self) -> String {
        let cells: Vec<Vec<String>> = self
            .rows
            .iter()
            .map(|r| r.iter().map(Cell::display).collect())
            .collect();
        let widths: Vec<usize> = (0..self.columns.len())
            .map(|j| {
                cells
                    .iter()
                    .map(|r| r[j].chars().count())
                    .chain([self.columns[j].1.chars().count()])
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        // Columns of text (and empty cells) are left-aligned, numbers right-aligned.
        let left: Vec<bool> = (0..self.columns.len())
            .map(|j| {
                self.rows
                    .iter()
                    .all(|r| matches!(r[j], Cell::Text(_) | Cell::Empty))
            })
            .collect();
        let mut out = String::new();
        let line = |out: &mut String, row: &[String]| {
            for (j, c) in row.iter().enumerate() {
                let w = widths[j];
                let sep = if j == 0 { "" } else { "  " };
                if left[j] {
                    let _ = write!(out, "{sep}{c:<w$}");
                } else {
                    let _ = write!(out, "{sep}{c:>w$}");
                }
            }
            let end = out.trim_end_matches(' ').len();
            out.truncate(end);
            out.push('\n');
        };
        let header: Vec<String> = self.columns.iter().map(|(_, h)| h.clone()).collect();
        line(&mut out, &header);
        let rule: Vec<String> = widths.iter().map(|&w| "-".repeat(w)).collect();
        line(&mut out, &rule);
        for r in &cells {
            line(&mut out, r);
        }
        out
    }

    pub fn to_csv(&self) -> String {
        let mut out = self
            .columns
            .iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join(",");
        out.push('\n');
        for r in &self.rows {
            out.push_str(&r.iter().map(Cell::csv).collect::<Vec<_>>().join(","));
            out.push('\n');
        }
        out
    }

    pub fn to_json(&self) -> serde_json::Value {
        serde_json::Value::Array(
            self.rows
                .iter()
                .map(|r| {
                    serde_json::Value::Object(
                        self.columns
                            .iter()
                            .zip(r)
                            .map(|((n, _), c)| (n.clone(), c.json()))
                            .collect(),
                    )
                })
                .collect(),
        )
    }

    pub fn write_csv(&self, path: &Path) -> Result<(), OutputError> {
        write_file(path, &self.to_csv())
    }
}

/// Creates the parent folder of an output path if it is missing (the reports write
/// into `renders/...` folders that may not exist yet).
pub fn create_parent(path: &Path) -> Result<(), OutputError> {
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir).map_err(|source| OutputError::Folder {
            path: path.to_path_buf(),
            folder: dir.to_path_buf(),
            source,
        }),
        None => Ok(()),
    }
}

/// Writes `text` to `path` (creating the parent folder) through a temporary file
/// renamed on success ([`crate::output`]).
pub fn write_file(path: &Path, text: &str) -> Result<(), OutputError> {
    create_parent(path)?;
    Output::check_as(path, Kind::Csv)?.write_bytes(text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_csv_json_agree() {
        let mut t = Table::new(&[("name", "name"), ("x_s", "x (s)"), ("n", "n")]);
        t.push(vec![Cell::text("a,b"), Cell::num(1.23456, 2), Cell::int(3)]);
        t.push(vec![Cell::text("c"), Cell::Empty, Cell::sci(f64::INFINITY)]);
        let text = t.to_text();
        assert!(text.contains("1.23") && text.contains("x (s)"), "{text}");
        assert_eq!(t.to_csv(), "name,x_s,n\n\"a,b\",1.23456,3\nc,,inf\n");
        let j = t.to_json();
        assert_eq!(j[0]["x_s"], 1.23456);
        assert!(j[1]["x_s"].is_null() && j[1]["n"].is_null());
    }
}
