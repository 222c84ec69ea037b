//! The `material.*` shape attributes.
//!
//! A shape's material is a set of *overrides*: the attributes that rules have
//! set (`color`, `set(material.x, v)`, `texture`, `setMaterial`). The geometry
//! keeps its own materials (an inserted asset's MTL materials, or defaults);
//! at output each face's material is its own with the overrides applied. So
//! `color("#111111") i("frame.obj")` colours the asset, and an asset's
//! textures survive unless a rule sets them.

use std::sync::Arc;

use cga_geometry::{Material, TEXTURE_CHANNELS};
use cga_value::Value;

/// One settable material attribute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MatField {
    /// Component 0..3 of the diffuse colour.
    Color(u8),
    Ambient(u8),
    Specular(u8),
    Emissive(u8),
    Opacity,
    Reflectivity,
    Shininess,
    BumpValue,
    Metallic,
    Roughness,
    DoubleSided,
    Name,
    Shader,
    OpacityMapMode,
    OpacityMapCutoff,
    /// Texture channel path.
    Map(u8),
    /// Texture channel transform: 0 su, 1 sv, 2 tu, 3 tv, 4 rw.
    MapXform(u8, u8),
    /// `material.color.rgb`: the colour as `#rrggbb`.
    ColorHex,
}

impl MatField {
    /// Bit position in the override mask.
    fn bit(self) -> u32 {
        match self {
            MatField::Color(i) => i as u32,
            MatField::Ambient(i) => 3 + i as u32,
            MatField::Specular(i) => 6 + i as u32,
            MatField::Emissive(i) => 9 + i as u32,
            MatField::Opacity => 12,
            MatField::Reflectivity => 13,
            MatField::Shininess => 14,
            MatField::BumpValue => 15,
            MatField::Metallic => 16,
            MatField::Roughness => 17,
            MatField::DoubleSided => 18,
            MatField::Name => 19,
            MatField::Shader => 20,
            MatField::OpacityMapMode => 21,
            MatField::OpacityMapCutoff => 22,
            MatField::Map(c) => 23 + c as u32 * 6,
            MatField::MapXform(c, k) => 23 + c as u32 * 6 + 1 + k as u32,
            MatField::ColorHex => 0,
        }
    }

    /// Parses `material.color.r`, `material.colormap.su`, ... (with the `material.` prefix).
    pub fn parse(name: &str) -> Option<MatField> {
        let rest = name.strip_prefix("material.")?;
        // Names of before 2011.1 (cga_changelog.md): `material.bump` became
        // `bumpValue`, `map3`/`map4`/`map5` the specular, opacity and
        // normal maps.
        let renamed;
        let rest = match rest.split_once('.').map_or((rest, ""), |(h, t)| (h, t)) {
            ("bump", "") => "bumpValue",
            (old @ ("map3" | "map4" | "map5"), tail) => {
                let new = match old {
                    "map3" => "specularmap",
                    "map4" => "opacitymap",
                    _ => "normalmap",
                };
                renamed = if tail.is_empty() {
                    new.to_string()
                } else {
                    format!("{new}.{tail}")
                };
                renamed.as_str()
            }
            _ => rest,
        };
        let rgb = |s: &str| match s {
            "r" => Some(0u8),
            "g" => Some(1),
            "b" => Some(2),
            _ => None,
        };
        if let Some((head, tail)) = rest.split_once('.') {
            return match head {
                "color" if tail == "rgb" => Some(MatField::ColorHex),
                // An older name of the opacity, still used in the reference's examples.
                "color" if tail == "a" => Some(MatField::Opacity),
                "color" => rgb(tail).map(MatField::Color),
                "ambient" => rgb(tail).map(MatField::Ambient),
                "specular" => rgb(tail).map(MatField::Specular),
                "emissive" => rgb(tail).map(MatField::Emissive),
                "opacitymap" if tail == "mode" => Some(MatField::OpacityMapMode),
                "opacitymap" if tail == "cutoff" => Some(MatField::OpacityMapCutoff),
                _ => {
                    let c = TEXTURE_CHANNELS.iter().position(|&ch| ch == head)? as u8;
                    let k = ["su", "sv", "tu", "tv", "rw"]
                        .iter()
                        .position(|&x| x == tail)? as u8;
                    Some(MatField::MapXform(c, k))
                }
            };
        }
        Some(match rest {
            "opacity" => MatField::Opacity,
            "reflectivity" => MatField::Reflectivity,
            "shininess" => MatField::Shininess,
            "bumpValue" => MatField::BumpValue,
            "metallic" => MatField::Metallic,
            "roughness" => MatField::Roughness,
            "doubleSided" => MatField::DoubleSided,
            "name" => MatField::Name,
            "shader" => MatField::Shader,
            _ => MatField::Map(TEXTURE_CHANNELS.iter().position(|&ch| ch == rest)? as u8),
        })
    }

    pub fn get(self, m: &Material) -> Value {
        let f = Value::Float;
        match self {
            MatField::Color(i) => f(m.color[i as usize]),
            MatField::Ambient(i) => f(m.ambient[i as usize]),
            MatField::Specular(i) => f(m.specular[i as usize]),
            MatField::Emissive(i) => f(m.emissive[i as usize]),
            MatField::Opacity => f(m.opacity),
            MatField::Reflectivity => f(m.reflectivity),
            MatField::Shininess => f(m.shininess),
            MatField::BumpValue => f(m.bump_value),
            MatField::Metallic => f(m.metallic),
            MatField::Roughness => f(m.roughness),
            MatField::DoubleSided => Value::Bool(m.double_sided),
            MatField::Name => Value::Str(m.name.clone()),
            MatField::Shader => Value::Str(m.shader.clone()),
            MatField::OpacityMapMode => Value::Str(m.opacitymap_mode.clone()),
            MatField::OpacityMapCutoff => f(m.opacitymap_cutoff),
            MatField::Map(c) => Value::Str(m.maps[c as usize].path.clone()),
            MatField::MapXform(c, k) => {
                let ch = &m.maps[c as usize];
                f([ch.su, ch.sv, ch.tu, ch.tv, ch.rw][k as usize])
            }
            MatField::ColorHex => Value::Str(Arc::from(rgb_to_hex(m.color).as_str())),
        }
    }

    /// Writes `v` into `m`; the error says what type was expected.
    pub fn set(self, m: &mut Material, v: &Value) -> Result<(), String> {
        let num = || match v {
            Value::Float(x) => Ok(*x),
            Value::Bool(b) => Ok(if *b { 1.0 } else { 0.0 }),
            Value::Str(s) => s
                .trim()
                .parse::<f64>()
                .map_err(|_| format!("expected a float, found the string \"{s}\"")),
            _ => Err("expected a float".to_string()),
        };
        let text = || -> Result<Arc<str>, String> {
            Ok(match v {
                Value::Str(s) => s.clone(),
                other => Arc::from(crate::values::to_text(other).as_str()),
            })
        };
        match self {
            MatField::Color(i) => m.color[i as usize] = num()?.clamp(0.0, 1.0),
            MatField::Ambient(i) => m.ambient[i as usize] = num()?.clamp(0.0, 1.0),
            MatField::Specular(i) => m.specular[i as usize] = num()?.clamp(0.0, 1.0),
            MatField::Emissive(i) => m.emissive[i as usize] = num()?.clamp(0.0, 1.0),
            MatField::Opacity => m.opacity = num()?.clamp(0.0, 1.0),
            MatField::Reflectivity => m.reflectivity = num()?,
            MatField::Shininess => m.shininess = num()?,
            MatField::BumpValue => m.bump_value = num()?,
            MatField::Metallic => m.metallic = num()?,
            MatField::Roughness => m.roughness = num()?,
            MatField::DoubleSided => {
                m.double_sided = match v {
                    Value::Bool(b) => *b,
                    Value::Str(s) => &**s == "true",
                    other => num()
                        .map(|x| x != 0.0)
                        .unwrap_or(matches!(other, Value::Bool(true))),
                }
            }
            MatField::Name => m.name = text()?,
            MatField::Shader => m.shader = text()?,
            MatField::OpacityMapMode => m.opacitymap_mode = text()?,
            MatField::OpacityMapCutoff => m.opacitymap_cutoff = num()?,
            MatField::Map(c) => m.maps[c as usize].path = text()?,
            MatField::MapXform(c, k) => {
                let x = num()?;
                let ch = &mut m.maps[c as usize];
                match k {
                    0 => ch.su = x,
                    1 => ch.sv = x,
                    2 => ch.tu = x,
                    3 => ch.tv = x,
                    _ => ch.rw = x,
                }
            }
            MatField::ColorHex => {
                let s = text()?;
                let (rgb, _) = parse_hex_color(&s)
                    .ok_or_else(|| format!("\"{s}\" is not a colour (#rrggbb)"))?;
                m.color = rgb;
            }
        }
        Ok(())
    }

    fn copy(self, from: &Material, to: &mut Material) {
        match self {
            MatField::ColorHex => to.color = from.color,
            MatField::Map(c) => to.maps[c as usize].path = from.maps[c as usize].path.clone(),
            _ => {
                let _ = self.set(to, &self.get(from));
            }
        }
    }
}

/// The material attributes a shape has set, to apply over its geometry's own.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialOverrides {
    pub values: Material,
    set: u128,
    /// The fields in the order they were first set (replayed on output).
    fields: Vec<MatField>,
}

impl MaterialOverrides {
    pub fn set(&mut self, field: MatField, v: &Value) -> Result<(), String> {
        field.set(&mut self.values, v)?;
        let fields: &[MatField] = match field {
            MatField::ColorHex => &[MatField::Color(0), MatField::Color(1), MatField::Color(2)],
            _ => std::slice::from_ref(&field),
        };
        for &f in fields {
            let bit = 1u128 << f.bit();
            if self.set & bit == 0 {
                self.set |= bit;
                self.fields.push(f);
            }
        }
        Ok(())
    }

    pub fn is_set(&self, field: MatField) -> bool {
        self.set & (1u128 << field.bit()) != 0
    }

    pub fn is_empty(&self) -> bool {
        self.set == 0
    }

    /// The value a rule reads for `field`: the override if set, else the
    /// geometry's first material's.
    pub fn get(&self, field: MatField, geometry_material: Option<&Material>) -> Value {
        if self.is_set(field) || geometry_material.is_none() {
            field.get(&self.values)
        } else {
            field.get(geometry_material.unwrap_or(&self.values))
        }
    }

    /// `base` with the overrides applied.
    pub fn apply(&self, base: &Material) -> Material {
        let mut m = base.clone();
        for &f in &self.fields {
            f.copy(&self.values, &mut m);
        }
        m
    }
}

/// Parses `#rrggbb` or `#rrggbboo` into colour and opacity.
pub fn parse_hex_color(s: &str) -> Option<([f64; 3], Option<f64>)> {
    let h = s.trim().strip_prefix('#')?.as_bytes();
    if !(h.len() == 6 || h.len() == 8) {
        return None;
    }
    // Digit by digit: `color("#...")` runs for most leaf shapes, and
    // `u8::from_str_radix` took most of its time.
    let digit = |c: u8| char::from(c).to_digit(16);
    let byte = |i: usize| Some((digit(h[i])? * 16 + digit(h[i + 1])?) as f64 / 255.0);
    let rgb = [byte(0)?, byte(2)?, byte(4)?];
    let o = if h.len() == 8 { Some(byte(6)?) } else { None };
    Some((rgb, o))
}

pub fn rgb_to_hex(c: [f64; 3]) -> String {
    let b = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    format!("#{:02x}{:02x}{:02x}", b(c[0]), b(c[1]), b(c[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_hex_colours() {
        assert_eq!(
            parse_hex_color("#ff8000"),
            Some(([1.0, 128.0 / 255.0, 0.0], None))
        );
        assert_eq!(
            parse_hex_color(" #FFfF0a80 "),
            Some(([1.0, 1.0, 10.0 / 255.0], Some(128.0 / 255.0)))
        );
        for bad in [
            "#ff80", "ff8000", "#gg0000", "#+f+f+f", "#ff80001", "#ff800é", "",
        ] {
            assert_eq!(parse_hex_color(bad), None, "{bad}");
        }
    }

    #[test]
    fn parses_field_names() {
        assert_eq!(
            MatField::parse("material.color.r"),
            Some(MatField::Color(0))
        );
        assert_eq!(MatField::parse("material.dirtmap"), Some(MatField::Map(2)));
        assert_eq!(
            MatField::parse("material.colormap.su"),
            Some(MatField::MapXform(0, 0))
        );
        assert_eq!(MatField::parse("material.nothing"), None);
    }

    #[test]
    fn overrides_apply_over_asset_material() {
        let mut o = MaterialOverrides::default();
        o.set(MatField::ColorHex, &Value::str("#111111")).unwrap();
        let mut asset = Material::default();
        asset.maps[0].path = Arc::from("wood.jpg");
        let m = o.apply(&asset);
        assert!((m.color[0] - 17.0 / 255.0).abs() < 1e-12);
        assert_eq!(m.colormap(), "wood.jpg");
    }
}
