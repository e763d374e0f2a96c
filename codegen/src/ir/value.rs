//! Values of entries (defaults, limits, DCF parameter values).

use serde::{Deserialize, Serialize};

/// A value in its data type's natural form.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Value {
    /// Integer, BOOLEAN (0/1) and TIME types. Wide enough for INTEGER64 and UNSIGNED64.
    Integer(i128),
    Real(f64),
    Text(String),
    Bytes(Vec<u8>),
}

/// A value as written in the source, possibly relative to the node id.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
}
