//! Values of entries (defaults, limits, DCF parameter values).

use std::ops::RangeInclusive;

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::{DataType, Entry};

/// The node ids CiA 301 allows (1..=127).
pub const NODE_IDS: RangeInclusive<u8> = 1..=127;

/// A value in its data type's natural form.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Value {
    /// Integer, BOOLEAN (0/1) and TIME types. Wide enough for INTEGER64 and UNSIGNED64.
    Integer(i128),
    Real(f64),
    Text(String),
    Bytes(Vec<u8>),
}

/// A value as written in the source, possibly relative to the node id.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Literal {
    /// The value, without the node id when `plus_node_id` is set.
    pub value: Value,
    /// The source wrote `$NODEID + value`; resolved only on request.
    pub plus_node_id: bool,
    /// The text as written in the source.
    pub text: String,
}

impl Literal {
    /// The value with `$NODEID` replaced by `node_id` (when given).
    ///
    /// A node-relative integer stays unresolved (the offset alone) when no node
    /// id is given.
    pub fn resolve(&self, node_id: Option<u8>) -> Value {
        match (&self.value, self.plus_node_id, node_id) {
            (Value::Integer(v), true, Some(n)) => Value::Integer(v + i128::from(n)),
            (v, _, _) => v.clone(),
        }
    }

    /// The value for node `node_id`, checked against the range of
    /// `data_type`: a `$NODEID` formula whose result leaves the type is an
    /// error (saying why), never a wrapped or out-of-range number.
    pub fn resolve_checked(&self, node_id: u8, data_type: DataType) -> Result<Value, String> {
        let value = self.resolve(Some(node_id));
        if !self.plus_node_id {
            return Ok(value);
        }
        match (&value, data_type.integer_range()) {
            (Value::Integer(v), Some((low, high))) if *v < low || *v > high => Err(format!(
                "`{}` gives {v} for node id {node_id}, out of range for {} ({low}..={high})",
                self.text.trim(),
                data_type.name()
            )),
            _ => Ok(value),
        }
    }
}

/// The node ids (1..=127) for which `offset + node id` lies in
/// `low..=high`; `None` when there is none.
pub fn fitting_node_ids(offset: i128, low: i128, high: i128) -> Option<RangeInclusive<u8>> {
    let first = (low.saturating_sub(offset)).max(i128::from(*NODE_IDS.start()));
    let last = (high.saturating_sub(offset)).min(i128::from(*NODE_IDS.end()));
    // Both lie in 1..=127 when first <= last.
    (first <= last).then_some(first as u8..=last as u8)
}

/// Why a `$NODEID + offset` formula of an integer type does not fit the
/// type for some node ids, or `None` when it fits for all of them. The
/// second part is true when some node ids fit.
pub fn node_formula_problem(
    text: &str,
    offset: i128,
    data_type: DataType,
) -> Option<(String, bool)> {
    let (low, high) = data_type.integer_range()?;
    let text = text.trim();
    let ty = data_type.name();
    match fitting_node_ids(offset, low, high) {
        None => Some((
            format!("`{text}` is out of range for {ty} ({low}..={high}) for every node id 1..=127"),
            false,
        )),
        Some(fit) if fit == NODE_IDS => None,
        Some(fit) => {
            let (a, b) = (*fit.start(), *fit.end());
            let bad = if a > 1 {
                format!("1..={}", a - 1)
            } else {
                format!("{}..=127", b + 1)
            };
            Some((
                format!(
                    "`{text}` is out of range for {ty} ({low}..={high}) for node ids {bad}; \
                     it fits node ids {a}..={b} only"
                ),
                true,
            ))
        }
    }
}

/// The values of `entry` that leave its type once `$NODEID` is node
/// `node_id`: the EDS key of each (`DefaultValue`, `ParameterValue`,
/// `LowLimit`, `HighLimit`) and why.
pub fn node_value_problems(entry: &Entry, node_id: u8) -> Vec<(&'static str, String)> {
    [
        ("DefaultValue", &entry.default),
        ("ParameterValue", &entry.parameter_value),
        ("LowLimit", &entry.low_limit),
        ("HighLimit", &entry.high_limit),
    ]
    .into_iter()
    .filter_map(|(key, literal)| {
        let why = literal
            .as_ref()?
            .resolve_checked(node_id, entry.data_type)
            .err()?;
        Some((key, why))
    })
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_ids_that_fit() {
        assert_eq!(fitting_node_ids(0x180, 0, 0x7FF), Some(1..=127));
        assert_eq!(fitting_node_ids(250, 0, 255), Some(1..=5));
        assert_eq!(fitting_node_ids(300, 0, 255), None);
        assert_eq!(fitting_node_ids(-10, 0, 255), Some(10..=127));
        assert_eq!(
            fitting_node_ids(i128::from(u64::MAX), 0, i128::from(u64::MAX)),
            None
        );
        assert!(node_formula_problem("$NODEID+0x180", 0x180, DataType::Unsigned32).is_none());
        let (m, some) = node_formula_problem("$NODEID+250", 250, DataType::Unsigned8).unwrap();
        assert!(
            some && m.contains("node ids 6..=127") && m.contains("1..=5"),
            "{m}"
        );
    }

    #[test]
    fn resolved_values_are_checked() {
        let l = Literal {
            value: Value::Integer(300),
            plus_node_id: true,
            text: "$NODEID+300".into(),
        };
        assert!(l.resolve_checked(5, DataType::Unsigned8).is_err());
        assert_eq!(
            l.resolve_checked(5, DataType::Unsigned16),
            Ok(Value::Integer(305))
        );
    }
}
