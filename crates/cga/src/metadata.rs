//! What a model says of its lots (glTF node `extras`, 3D Tiles property
//! tables): a lot's index and attributes, and its reports.

use cga_export::serde_json;

use crate::{Lot, Value};

/// A lot's node `extras` in glTF (and its row of a 3D Tiles property
/// table): its index and its own attributes (a GIS feature's properties).
pub fn lot_metadata(index: usize, lot: &Lot) -> serde_json::Value {
    use serde_json::{json, Map, Value as Json};
    fn number(x: f64) -> Json {
        serde_json::Number::from_f64(x).map_or(Json::Null, Json::Number)
    }
    fn to_json(v: &Value) -> Json {
        match v {
            Value::Float(x) => number(*x),
            Value::Bool(b) => Json::Bool(*b),
            Value::Str(s) => Json::String(s.to_string()),
            Value::FloatArray(a) => a.data.iter().map(|x| number(*x)).collect(),
            Value::BoolArray(a) => a.data.iter().map(|b| Json::Bool(*b)).collect(),
            Value::StrArray(a) => a.data.iter().map(|s| Json::String(s.to_string())).collect(),
        }
    }
    let attributes: Map<String, Json> = lot
        .attrs
        .iter()
        .map(|(k, v)| (k.to_string(), to_json(v)))
        .collect();
    json!({ "lot": index, "attributes": attributes })
}

/// A lot's reports as its model's metadata: per key the sum of its
/// numbers (CityEngine's report sum), or the last value of a key whose
/// values are strings or booleans.
pub fn reports_metadata(reports: &[(String, Value)]) -> serde_json::Value {
    use serde_json::{Map, Value as Json};
    let mut out: Map<String, Json> = Map::new();
    for (key, v) in reports {
        let value = match (v, out.get(key).and_then(Json::as_f64)) {
            (Value::Float(x), Some(sum)) => Json::from(sum + x),
            (Value::Float(x), None) if !out.contains_key(key) => Json::from(*x),
            (v, _) => Json::String(crate::value_text(v)),
        };
        out.insert(key.clone(), value);
    }
    Json::Object(out)
}
