//! The model as the page reads it, and values as JSON.
//!
//! Binary model (`/api/model.bin`, `/api/lots.bin`), little-endian:
//!
//! ```text
//! "CGAM"  u32 header length H  header (JSON, H bytes, padded with spaces to 4)
//! data: per mesh, positions (f32 x 3 per vertex), texture coordinates
//!       (f32 x 2), normals (i8 x 3, x 127), indices (u16 or u32 x 3 per
//!       triangle: "index_bytes"); each array padded to 4 bytes
//! ```
//!
//! The header: `{"origin": [x, y, z], "lots": [{"index", "name", "meshes": [{"mesh", "vertices",
//! "triangles", "positions", "normals", "uvs", "indices", "color",
//! "opacity", "material", "double_sided", "texture"}]}]}`, positions
//! relative to `origin` (the lots' centre when they lie far from the
//! frame's origin, else zero), offsets in bytes from the start of
//! the data. `mesh` is the mesh's number in the lot's plain model, which
//! [`cga::LotResult::provenance`] takes with a triangle number. The page
//! builds its three.js geometry from these arrays directly, with no glTF
//! parsing, and keeps the numbers a click needs for provenance.

use cga::{LotResult, Value};
use serde_json::{json, Value as Json};

/// The lots' meshes in the binary form above; `texture` gives the URL of
/// a colour map path as the rules wrote it (`None`: not found, drawn
/// without).
/// Positions are sent relative to `origin` (in the header's `origin`).
pub fn model(
    results: &[LotResult],
    origin: [f64; 3],
    texture: &mut dyn FnMut(&str) -> Option<String>,
) -> Vec<u8> {
    let mut data: Vec<u8> = Vec::new();
    let mut lots = Vec::with_capacity(results.len());
    for lot in results {
        let mut meshes = Vec::new();
        for (m, mesh) in lot.model.meshes.iter().enumerate() {
            if mesh.indices.is_empty() {
                continue;
            }
            let material = lot.model.materials.get(mesh.material);
            let positions = data.len();
            for p in &mesh.positions {
                for (c, o) in p.iter().zip(origin) {
                    data.extend_from_slice(&((*c - o) as f32).to_le_bytes());
                }
            }
            let uvs = data.len();
            for uv in &mesh.uvs {
                for c in uv {
                    data.extend_from_slice(&(*c as f32).to_le_bytes());
                }
            }
            // Unit normals need no more than a byte per coordinate (the
            // page reads them as normalised): a quarter of the bytes to
            // send, which is most of the time a model takes to arrive.
            let normals = data.len();
            for n in &mesh.normals {
                for c in n {
                    data.push(((c.clamp(-1.0, 1.0) * 127.0).round() as i8) as u8);
                }
            }
            pad(&mut data);
            let indices = data.len();
            let short = mesh.positions.len() <= 1 << 16;
            for t in &mesh.indices {
                for &i in t {
                    if short {
                        data.extend_from_slice(&(i as u16).to_le_bytes());
                    } else {
                        data.extend_from_slice(&i.to_le_bytes());
                    }
                }
            }
            pad(&mut data);
            meshes.push(json!({
                "mesh": m,
                "vertices": mesh.positions.len(),
                "triangles": mesh.indices.len(),
                "positions": positions,
                "normals": if mesh.normals.len() == mesh.positions.len() { json!(normals) } else { Json::Null },
                "uvs": if mesh.uvs.len() == mesh.positions.len() { json!(uvs) } else { Json::Null },
                "indices": indices,
                "index_bytes": if short { 2 } else { 4 },
                "texture": material.map(|m| m.colormap()).filter(|p| !p.is_empty()).and_then(&mut *texture),
                "color": material.map(|m| m.color).unwrap_or([0.8, 0.8, 0.8]),
                "opacity": material.map(|m| m.opacity).unwrap_or(1.0),
                "material": material.map(|m| m.name.to_string()).unwrap_or_default(),
                "double_sided": material.map(|m| m.double_sided).unwrap_or(false),
            }));
        }
        lots.push(json!({"index": lot.index, "name": lot.name, "meshes": meshes}));
    }
    let header = json!({ "lots": lots, "origin": origin });
    let mut header = serde_json::to_vec(&header).expect("JSON of plain data");
    while !header.len().is_multiple_of(4) {
        header.push(b' ');
    }
    let mut out = Vec::with_capacity(8 + header.len() + data.len());
    out.extend_from_slice(b"CGAM");
    out.extend_from_slice(&(header.len() as u32).to_le_bytes());
    out.extend_from_slice(&header);
    out.extend_from_slice(&data);
    out
}

/// Zeros up to a multiple of 4 bytes: typed arrays over the data must
/// start aligned.
fn pad(data: &mut Vec<u8>) {
    while !data.len().is_multiple_of(4) {
        data.push(0);
    }
}

/// A CGA value as JSON: numbers (non-finite ones as their text), booleans,
/// strings, arrays as (nested, for tables) arrays.
pub fn value(v: &Value) -> Json {
    match v {
        Value::Float(f) => number(*f),
        Value::Bool(b) => json!(b),
        Value::Str(s) => json!(s.as_ref()),
        _ => json!(cga::value_text(v)),
    }
}

fn number(f: f64) -> Json {
    serde_json::Number::from_f64(f)
        .map(Json::Number)
        .unwrap_or_else(|| json!(f.to_string()))
}

/// A value the page sent for an attribute of type `ty`, as the engine
/// takes it; `None` when it does not fit (the attribute keeps its
/// default).
pub fn attr_value(ty: Option<cga::ValueType>, v: &Json) -> Option<Value> {
    use cga::ValueType as T;
    match (ty, v) {
        (Some(T::Float), Json::Number(n)) => n.as_f64().map(Value::Float),
        (Some(T::Float), Json::String(s)) => s.trim().parse().ok().map(Value::Float),
        (Some(T::Bool), Json::Bool(b)) => Some(Value::Bool(*b)),
        (Some(T::Bool), Json::String(s)) => match s.as_str() {
            "true" => Some(Value::Bool(true)),
            "false" => Some(Value::Bool(false)),
            _ => None,
        },
        (Some(T::Str), Json::String(s)) => Some(Value::Str(s.as_str().into())),
        (Some(T::Str), Json::Number(n)) => Some(Value::Str(n.to_string().into())),
        (Some(T::FloatArray | T::BoolArray | T::StrArray), Json::String(s)) => {
            Some(cga::parse_value(s))
        }
        (None, Json::Number(n)) => n.as_f64().map(Value::Float),
        (None, Json::Bool(b)) => Some(Value::Bool(*b)),
        (None, Json::String(s)) => Some(cga::parse_value(s)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_model_reads_back() {
        let engine = cga::Engine::new(cga::MemoryWorld::new());
        let rules = engine.load_text("/p/a.cga", "Lot --> extrude(7) color(\"#ff0000\") X.\n");
        assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
        let results = rules
            .generate_all(&[cga::lots::rect(10.0, 20.0)], &cga::Options::default())
            .unwrap();
        let bytes = model(&results, [0.0; 3], &mut |_| None);
        assert_eq!(&bytes[..4], b"CGAM");
        let h = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
        assert_eq!(h % 4, 0);
        let header: Json = serde_json::from_slice(&bytes[8..8 + h]).unwrap();
        let mesh = &header["lots"][0]["meshes"][0];
        assert_eq!(mesh["color"], json!([1.0, 0.0, 0.0]));
        // A box without its bottom? extrude keeps the lot face: 6 quads.
        assert_eq!(mesh["triangles"], json!(12));
        let data = &bytes[8 + h..];
        let vertices = mesh["vertices"].as_u64().unwrap() as usize;
        let at = mesh["positions"].as_u64().unwrap() as usize;
        let ys: Vec<f32> = (0..vertices)
            .map(|i| {
                let o = at + i * 12 + 4;
                f32::from_le_bytes(data[o..o + 4].try_into().unwrap())
            })
            .collect();
        let top = ys.iter().cloned().fold(f32::MIN, f32::max);
        assert_eq!(top, 7.0);
        let indices = mesh["indices"].as_u64().unwrap() as usize;
        // 12 triangles of 16-bit indices.
        assert_eq!(mesh["index_bytes"], 2);
        assert_eq!(data.len(), indices + 12 * 3 * 2);
        let normals = mesh["normals"].as_u64().unwrap() as usize;
        assert_eq!(indices, normals + (vertices * 3).next_multiple_of(4));
        let n: Vec<i8> = data[normals..normals + vertices * 3]
            .iter()
            .map(|&b| b as i8)
            .collect();
        // Every normal a unit axis, scaled by 127.
        for v in n.chunks(3) {
            assert_eq!(
                v.iter().map(|c| (*c as i32).abs()).sum::<i32>(),
                127,
                "{v:?}"
            );
        }
        assert_eq!(mesh["texture"], Json::Null);
    }

    #[test]
    fn far_lots_are_sent_relative_to_their_origin() {
        // A lot at 10,000 km: 32-bit floats there are a metre apart.
        let engine = cga::Engine::new(cga::MemoryWorld::new());
        let rules = engine.load_text("/p/a.cga", "Lot --> X.\n");
        let far = cga::DVec3::new(1e7, 0.0, -1e7);
        let corners = [0.0, 20.123].map(|x| far + cga::DVec3::new(x, 0.0, 0.0));
        let lot = cga::lots::polygon(
            "far",
            &[
                corners[0],
                corners[1],
                corners[1] - cga::DVec3::Z * 15.5,
                corners[0] - cga::DVec3::Z * 15.5,
            ],
        );
        let origin = cga::lots::local_origin(std::slice::from_ref(&lot)).unwrap();
        let results = rules
            .generate_all(&[lot], &cga::Options::default())
            .unwrap();
        let bytes = model(&results, origin.to_array(), &mut |_| None);
        let h = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
        let header: Json = serde_json::from_slice(&bytes[8..8 + h]).unwrap();
        assert_eq!(header["origin"], json!([1e7 + 10.0, 0.0, -1e7 - 8.0]));
        let mesh = &header["lots"][0]["meshes"][0];
        let data = &bytes[8 + h..];
        let at = mesh["positions"].as_u64().unwrap() as usize;
        let xs: Vec<f64> = (0..4)
            .map(|i| {
                f32::from_le_bytes(data[at + 12 * i..at + 12 * i + 4].try_into().unwrap()) as f64
            })
            .collect();
        let width = xs.iter().cloned().fold(f64::MIN, f64::max)
            - xs.iter().cloned().fold(f64::MAX, f64::min);
        assert!((width - 20.123).abs() < 1e-5, "{width}");
    }

    #[test]
    fn page_values_take_the_attribute_type() {
        use cga::ValueType as T;
        assert_eq!(
            attr_value(Some(T::Float), &json!(3.5)),
            Some(Value::Float(3.5))
        );
        assert_eq!(
            attr_value(Some(T::Float), &json!("12")),
            Some(Value::Float(12.0))
        );
        assert_eq!(attr_value(Some(T::Float), &json!("tall")), None);
        assert_eq!(
            attr_value(Some(T::Str), &json!("#ff0000")),
            Some(Value::Str("#ff0000".into()))
        );
        assert_eq!(
            attr_value(Some(T::Bool), &json!(true)),
            Some(Value::Bool(true))
        );
        assert_eq!(attr_value(Some(T::Bool), &json!(1)), None);
        assert_eq!(value(&Value::Float(f64::NAN)), json!("NaN"));
    }
}
