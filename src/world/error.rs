//! Errors in world files: each one names the file, the line and column, and the key.

use std::fmt;
use std::path::PathBuf;

/// One problem in one world file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WorldError {
    /// The file the problem is in.
    pub file: PathBuf,
    /// 1-based line and column of the offending key or value, when known.
    pub location: Option<(usize, usize)>,
    /// Dotted path of the offending key (`agents.0.mass`), when known.
    pub key: Option<String>,
    /// What is wrong and what was expected.
    pub message: String,
}

impl fmt::Display for WorldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some((line, column)) = self.location {
            write!(f, ":{line}:{column}")?;
        }
        write!(f, ": ")?;
        if let Some(key) = &self.key {
            write!(f, "`{key}`: ")?;
        }
        write!(f, "{}", self.message)
    }
}

/// Every problem found in a world file (never empty).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct WorldErrors(pub Vec<WorldError>);

impl WorldErrors {
    /// The errors in the order of the file: by line and column, unlocated ones last.
    pub fn in_file_order(mut errors: Vec<WorldError>) -> Self {
        errors.sort_by_key(|e| e.location.unwrap_or((usize::MAX, usize::MAX)));
        Self(errors)
    }
}

impl fmt::Display for WorldErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "error: {e}")?;
        }
        Ok(())
    }
}

/// Converts a byte offset in `text` to a 1-based (line, column), counting columns in characters.
pub fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[line_start..].chars().count() + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_column_counts_from_one() {
        let text = "a = 1\nbb = 2\n";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 6), (2, 1));
        assert_eq!(line_column(text, 11), (2, 6));
    }
}
