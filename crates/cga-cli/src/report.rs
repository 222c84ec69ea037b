//! `--report FILE.json`: the values of `report()` aggregated per key, as
//! `KEY_n`, `KEY_sum`, `KEY_avg`, `KEY_min`, `KEY_max`. Bool and string
//! reports cannot be summed: their statistics are the last value reported.

use std::collections::BTreeMap;

use cga::Value;

#[derive(Default)]
pub struct Reports {
    keys: BTreeMap<String, Stat>,
}

enum Stat {
    Float {
        n: usize,
        sum: f64,
        min: f64,
        max: f64,
    },
    Other {
        n: usize,
        last: Value,
    },
}

impl Reports {
    pub fn add(&mut self, values: &[(String, Value)]) {
        for (key, v) in values {
            let stat = self.keys.entry(key.clone()).or_insert_with(|| match v {
                Value::Float(_) => Stat::Float {
                    n: 0,
                    sum: 0.0,
                    min: f64::INFINITY,
                    max: f64::NEG_INFINITY,
                },
                _ => Stat::Other {
                    n: 0,
                    last: v.clone(),
                },
            });
            match (stat, v) {
                (Stat::Float { n, sum, min, max }, Value::Float(x)) => {
                    *n += 1;
                    *sum += x;
                    *min = min.min(*x);
                    *max = max.max(*x);
                }
                (Stat::Other { n, last }, v) => {
                    *n += 1;
                    *last = v.clone();
                }
                // A key reported with mixed types: count it, keep the float statistics.
                (Stat::Float { n, .. }, _) => *n += 1,
            }
        }
    }

    pub fn to_json(&self) -> String {
        let mut map = serde_json::Map::new();
        for (key, stat) in &self.keys {
            match stat {
                Stat::Float { n, sum, min, max } => {
                    map.insert(format!("{key}_avg"), json_num(sum / *n as f64));
                    map.insert(format!("{key}_max"), json_num(*max));
                    map.insert(format!("{key}_min"), json_num(*min));
                    map.insert(format!("{key}_n"), json_num(*n as f64));
                    map.insert(format!("{key}_sum"), json_num(*sum));
                }
                Stat::Other { n, last } => {
                    let v = match last {
                        Value::Bool(b) => serde_json::Value::Bool(*b),
                        Value::Str(s) => serde_json::Value::String(s.to_string()),
                        _ => serde_json::Value::Null,
                    };
                    for stat in ["avg", "max", "min", "sum"] {
                        map.insert(format!("{key}_{stat}"), v.clone());
                    }
                    map.insert(format!("{key}_n"), json_num(*n as f64));
                }
            }
        }
        let mut text = serde_json::to_string_pretty(&serde_json::Value::Object(map))
            .unwrap_or_else(|_| "{}".to_string());
        text.push('\n');
        text
    }
}

fn json_num(x: f64) -> serde_json::Value {
    serde_json::Number::from_f64(x)
        .map(serde_json::Value::Number)
        .unwrap_or(serde_json::Value::Null)
}
