//! "Did you mean …?" for unknown keys and variants: the expected name closest to a typo.

/// Appends a suggestion to a serde message of the form
/// ``unknown field `masss`, expected one of `name`, `mass`, …`` (or ``unknown variant``), when
/// one expected name is within two edits of the unknown one.
pub fn with_suggestion(message: &str) -> String {
    let Some(rest) = message
        .strip_prefix("unknown field `")
        .or_else(|| message.strip_prefix("unknown variant `"))
    else {
        return message.to_string();
    };
    let Some((unknown, expected)) = rest.split_once('`') else {
        return message.to_string();
    };
    match closest(unknown, expected.split('`').skip(1).step_by(2)) {
        Some(candidate) => format!("{message}; did you mean `{candidate}`?"),
        None => message.to_string(),
    }
}

/// The candidate within two edits of `unknown` that is closest to it, if any.
pub fn closest<'a>(
    unknown: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    candidates
        .into_iter()
        .map(|candidate| (edit_distance(unknown, candidate), candidate))
        .filter(|(d, _)| *d <= 2)
        .min_by_key(|(d, _)| *d)
        .map(|(_, candidate)| candidate)
}

/// Levenshtein distance, in characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let above = row[j + 1];
            row[j + 1] = (above + 1)
                .min(row[j] + 1)
                .min(diagonal + usize::from(ca != *cb));
            diagonal = above;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_the_nearest_expected_name() {
        let m = "unknown field `masss`, expected one of `name`, `start`, `mass`";
        assert_eq!(with_suggestion(m), format!("{m}; did you mean `mass`?"));
        let m = "unknown variant `nadv`, expected `nadf` or `viscous`";
        assert!(with_suggestion(m).ends_with("did you mean `nadf`?"));
    }

    #[test]
    fn says_nothing_when_no_name_is_close() {
        let m = "unknown field `colour`, expected one of `name`, `start`";
        assert_eq!(with_suggestion(m), m);
        assert_eq!(
            with_suggestion("invalid type: string"),
            "invalid type: string"
        );
    }

    #[test]
    fn edit_distance_counts_insertions_deletions_and_substitutions() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "ab"), 2);
        assert_eq!(edit_distance("mass", "mass"), 0);
    }
}
