//! `--report FILE.json`: the values of `report()`, aggregated per key over
//! all lots (`KEY_n`, `KEY_sum`, `KEY_avg`, `KEY_min`, `KEY_max`, as
//! CityEngine's runtime writes them), and the same per lot under `lots`
//! (`[{ "id", "index", "reports" }]`). Bool and string reports cannot be
//! summed: `KEY_counts` says how often each value was reported, and, as
//! CityEngine's runtime writes them, `KEY_avg` ... `KEY_sum` hold the last
//! value reported.

use std::collections::BTreeMap;

use cga::Value;

/// Reports aggregated per key.
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
    /// Bool and string values: how often each was reported, and the last.
    Counts {
        n: usize,
        counts: BTreeMap<String, usize>,
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
                _ => Stat::Counts {
                    n: 0,
                    counts: BTreeMap::new(),
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
                (Stat::Counts { n, counts, last }, v) => {
                    *n += 1;
                    *counts.entry(cga::value_text(v)).or_default() += 1;
                    *last = v.clone();
                }
                // A key reported with mixed types: count it, keep the float statistics.
                (Stat::Float { n, .. }, _) => *n += 1,
            }
        }
    }

    /// The statistics as a JSON object.
    pub fn to_map(&self) -> serde_json::Map<String, serde_json::Value> {
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
                Stat::Counts { n, counts, last } => {
                    let v = match last {
                        Value::Bool(b) => serde_json::Value::Bool(*b),
                        Value::Str(s) => serde_json::Value::String(s.to_string()),
                        _ => serde_json::Value::Null,
                    };
                    for stat in ["avg", "max", "min", "sum"] {
                        map.insert(format!("{key}_{stat}"), v.clone());
                    }
                    let counts = counts
                        .iter()
                        .map(|(v, c)| (v.clone(), json_num(*c as f64)))
                        .collect();
                    map.insert(format!("{key}_counts"), serde_json::Value::Object(counts));
                    map.insert(format!("{key}_n"), json_num(*n as f64));
                }
            }
        }
        map
    }
}

/// The report file: totals over all lots, and each lot's own.
#[derive(Default)]
pub struct ReportFile {
    totals: Reports,
    lots: Vec<serde_json::Value>,
}

impl ReportFile {
    /// Adds the reports of lot `index` called `id`, in lot order.
    pub fn add_lot(&mut self, index: usize, id: &str, values: &[(String, Value)]) {
        self.totals.add(values);
        let mut own = Reports::default();
        own.add(values);
        self.lots.push(serde_json::json!({
            "id": id,
            "index": index,
            "reports": serde_json::Value::Object(own.to_map()),
        }));
    }

    pub fn to_json(&self) -> String {
        let mut map = self.totals.to_map();
        map.insert("lots".into(), serde_json::Value::Array(self.lots.clone()));
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn totals_per_key_and_per_lot_with_counts_for_strings() {
        let mut file = ReportFile::default();
        file.add_lot(
            0,
            "a",
            &[
                ("area".into(), Value::Float(2.0)),
                ("area".into(), Value::Float(4.0)),
                ("roof".into(), Value::from("flat")),
            ],
        );
        file.add_lot(
            1,
            "b",
            &[
                ("area".into(), Value::Float(6.0)),
                ("roof".into(), Value::from("gable")),
                ("roof".into(), Value::from("flat")),
                ("lit".into(), Value::Bool(true)),
            ],
        );
        let v: serde_json::Value = serde_json::from_str(&file.to_json()).unwrap();
        assert_eq!(v["area_sum"], 12.0);
        assert_eq!(v["area_n"], 3.0);
        assert_eq!(v["area_avg"], 4.0);
        assert_eq!(v["roof_n"], 3.0);
        assert_eq!(
            v["roof_counts"],
            serde_json::json!({ "flat": 2.0, "gable": 1.0 })
        );
        assert_eq!(v["lit_counts"], serde_json::json!({ "true": 1.0 }));
        // The last value, as CityEngine's runtime writes string reports.
        assert_eq!(v["roof_sum"], "flat");
        let lots = v["lots"].as_array().unwrap();
        assert_eq!(lots.len(), 2);
        assert_eq!(lots[0]["id"], "a");
        assert_eq!(lots[0]["reports"]["area_sum"], 6.0);
        assert_eq!(lots[1]["index"], 1);
        assert_eq!(lots[1]["reports"]["roof_counts"]["gable"], 1.0);
    }
}
