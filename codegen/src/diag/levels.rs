//! What a user says about a rule: allow it (its warnings are dropped), or
//! deny it (its warnings are errors). Set from a build script
//! (`Builder::allow`/`deny`), the command line (`--allow`/`--deny`) or a
//! YAML table's `diagnostics:` section.

use std::collections::BTreeMap;

use super::{Diagnostics, Severity, rules};

/// The level of one rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Level {
    /// Warnings of the rule are not reported. Errors stay errors: an input
    /// that cannot be used cannot be allowed.
    Allow,
    /// The rule's warnings are errors.
    Deny,
}

impl Level {
    pub fn as_str(self) -> &'static str {
        match self {
            Level::Allow => "allow",
            Level::Deny => "deny",
        }
    }
}

/// Rule levels by rule code, each with who set it (for the notes).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Levels {
    rules: BTreeMap<String, (Level, String)>,
}

impl Levels {
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets `code` to `level`; `by` says who set it (`the build script`,
    /// `--allow`, a file name), shown in the note of a denied warning. A
    /// later setting of the same code replaces an earlier one.
    pub fn set(&mut self, code: &str, level: Level, by: &str) {
        self.rules.insert(code.to_string(), (level, by.to_string()));
    }

    pub fn allow(&mut self, code: &str, by: &str) {
        self.set(code, Level::Allow, by);
    }

    pub fn deny(&mut self, code: &str, by: &str) {
        self.set(code, Level::Deny, by);
    }

    /// The level of `code`, if one was set.
    pub fn get(&self, code: &str) -> Option<Level> {
        self.rules.get(code).map(|(level, _)| *level)
    }

    pub fn is_empty(&self) -> bool {
        self.rules.is_empty()
    }

    /// Every setting, by code.
    pub fn iter(&self) -> impl Iterator<Item = (&str, Level)> {
        self.rules
            .iter()
            .map(|(code, (level, _))| (code.as_str(), *level))
    }

    /// `self` with every setting of `later` on top (`later` wins).
    pub fn merged(&self, later: &Levels) -> Levels {
        let mut out = self.clone();
        for (code, setting) in &later.rules {
            out.rules.insert(code.clone(), setting.clone());
        }
        out
    }

    /// The codes that name no rule, each with the closest known code when
    /// one is close.
    pub fn unknown(&self) -> Vec<(&str, Option<&'static str>)> {
        self.rules
            .keys()
            .filter(|code| !rules::is_known(code))
            .map(|code| (code.as_str(), rules::closest(code)))
            .collect()
    }
}

impl Diagnostics {
    /// Applies rule levels, then `strict`: an allowed rule's warnings are
    /// dropped (counted in [`Diagnostics::allowed_count`]); a denied rule's
    /// warnings, and with `strict` every remaining warning, become errors.
    /// Errors are never changed.
    pub fn apply_levels(&mut self, levels: &Levels, strict: bool) {
        self.flush_caps();
        let mut dropped = 0;
        self.items.retain(|d| {
            let keep = d.severity == Severity::Error || levels.get(d.code) != Some(Level::Allow);
            // A summary of left-out warnings counts for each of them.
            dropped += usize::from(!keep) * super::cap::summarised(d).unwrap_or(1);
            keep
        });
        self.allowed += dropped;
        for d in &mut self.items {
            if d.severity != Severity::Warning {
                continue;
            }
            if let Some((Level::Deny, by)) = levels.rules.get(d.code) {
                d.severity = Severity::Error;
                d.notes.push(format!(
                    "`{}` is denied by {by}: its warnings are errors",
                    d.code
                ));
            } else if strict {
                d.severity = Severity::Error;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::{Diagnostic, Location};

    fn warning(code: &'static str) -> Diagnostic {
        Diagnostic {
            severity: Severity::Warning,
            code,
            file: "a.eds".into(),
            location: Location::default(),
            message: "m".into(),
            notes: Vec::new(),
        }
    }

    #[test]
    fn allow_drops_warnings_deny_makes_errors_and_errors_stay() {
        let mut d = Diagnostics::new();
        d.push(warning("eds::unlisted-object"));
        d.push(warning("eds::unlisted-object"));
        d.push(warning("eds::pdo-mapping"));
        d.push(warning("eds::unknown-section"));
        let mut error = warning("eds::unlisted-object");
        error.severity = Severity::Error;
        d.push(error);
        let mut levels = Levels::new();
        levels.allow("eds::unlisted-object", "the build script");
        levels.deny("eds::pdo-mapping", "od/fixes.yaml");
        d.apply_levels(&levels, false);
        let kept: Vec<_> = d.iter().map(|d| (d.code, d.severity)).collect();
        assert_eq!(
            kept,
            [
                ("eds::pdo-mapping", Severity::Error),
                ("eds::unknown-section", Severity::Warning),
                ("eds::unlisted-object", Severity::Error),
            ]
        );
        assert_eq!(d.allowed_count(), 2);
        assert!(d.iter().next().unwrap().notes[0].contains("denied by od/fixes.yaml"));
    }

    #[test]
    fn strict_spares_allowed_rules() {
        let mut d = Diagnostics::new();
        d.push(warning("eds::unlisted-object"));
        d.push(warning("eds::unknown-section"));
        let mut levels = Levels::new();
        levels.allow("eds::unlisted-object", "--allow");
        d.apply_levels(&levels, true);
        assert_eq!(d.len(), 1);
        assert_eq!(d.error_count(), 1);
    }

    #[test]
    fn later_settings_win_and_unknown_codes_get_a_suggestion() {
        let mut file = Levels::new();
        file.deny("eds::unlisted-object", "a.yaml");
        let mut user = Levels::new();
        user.allow("eds::unlisted-object", "--allow");
        user.allow("eds::unlisted-objects", "--allow");
        let merged = file.merged(&user);
        assert_eq!(merged.get("eds::unlisted-object"), Some(Level::Allow));
        assert_eq!(
            merged.unknown(),
            [("eds::unlisted-objects", Some("eds::unlisted-object"))]
        );
    }
}
