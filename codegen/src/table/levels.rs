//! The `diagnostics:` section of a table (rule levels for its device), and
//! "did you mean" for an unknown key.

use serde_saphyr::Spanned;

use super::schema::DiagnosticsDef;
use super::{At, Ctx};
use crate::diag::{Level, Levels, rules};

/// The levels `def` sets, each rule code checked; an unknown code is an
/// error at its key, with the closest known code when there is one.
pub(super) fn read(ctx: &mut Ctx, def: Option<&Spanned<DiagnosticsDef>>) -> Levels {
    let mut levels = Levels::new();
    let Some(def) = def else { return levels };
    let by = ctx.file.to_string();
    let lists = [
        (Level::Allow, &def.value.allow),
        (Level::Deny, &def.value.deny),
    ];
    for (level, codes) in lists {
        for code in codes {
            if rules::is_known(&code.value) {
                levels.set(&code.value, level, &by);
                continue;
            }
            let mut message = format!("`{}` is not a diagnostic rule", code.value);
            if let Some(close) = rules::closest(&code.value) {
                message.push_str(&format!("; did you mean `{close}`?"));
            }
            ctx.error(
                "table::unknown-rule",
                At::of(code),
                "diagnostics",
                level.as_str(),
                message,
            );
        }
    }
    levels
}

/// For "unknown field `x`, expected one of a, b, c" (or "expected `a` or
/// `b`", keys with or without backticks): "did you mean `a`?" when a known
/// key is close to `x`.
pub(super) fn did_you_mean(message: &str) -> Option<String> {
    let rest = message.split("unknown field `").nth(1)?;
    let (unknown, expected) = rest.split_once('`')?;
    let expected = expected.split_once("expected")?.1;
    let expected = expected.trim_start().trim_start_matches("one of");
    let candidates: Vec<&str> = expected
        .split([',', ' '])
        .map(|word| word.trim().trim_matches('`'))
        .filter(|word| !word.is_empty() && *word != "or")
        .collect();
    let close = rules::closest_of(unknown, candidates.iter().copied())?;
    Some(format!("did you mean `{close}`?"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggestions_from_serde_messages() {
        assert_eq!(
            did_you_mean("unknown field `semantic`, expected one of `format`, `base`, `semantics`"),
            Some("did you mean `semantics`?".into())
        );
        assert_eq!(
            did_you_mean("unknown field `alow`, expected `allow` or `deny`"),
            Some("did you mean `allow`?".into())
        );
        assert_eq!(
            did_you_mean("unknown field `zzzzzz`, expected `allow` or `deny`"),
            None
        );
        assert_eq!(
            did_you_mean("unknown field `semantic`, expected one of format, base, semantics, pdos"),
            Some("did you mean `semantics`?".into())
        );
        assert_eq!(did_you_mean("invalid type: string"), None);
    }
}
