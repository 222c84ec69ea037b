//! Colour conversions of the utility library: hex strings (`"#rrggbb"`,
//! `"#rrggbboo"`) to and from RGB, HSV and opacity, and `colorRamp`.

use std::fmt::Write as _;

use super::{float_arg, str_arg};
use crate::error::ValueError;
use crate::value::Value;

/// The bytes of a hex colour: `[r, g, b, o]`, each `None` where the string
/// is too short or not hexadecimal there. A leading `#` is optional.
pub fn hex_to_rgba(hex: &str) -> [Option<u8>; 4] {
    let digits = hex.strip_prefix('#').unwrap_or(hex).as_bytes();
    let mut out = [None; 4];
    for (k, slot) in out.iter_mut().enumerate() {
        let pair = digits.get(2 * k..2 * k + 2);
        *slot = pair
            .and_then(|p| std::str::from_utf8(p).ok())
            .and_then(|p| u8::from_str_radix(p, 16).ok());
    }
    out
}

fn channel(args: &[Value], name: &str, k: usize) -> Result<Value, ValueError> {
    let hex = str_arg(args, 0, name)?;
    Ok(Value::Float(
        hex_to_rgba(hex)[k].map_or(0.0, |b| f64::from(b) / 255.0),
    ))
}

pub fn hex_to_r(args: &[Value]) -> Result<Value, ValueError> {
    channel(args, "colorHexToR", 0)
}

pub fn hex_to_g(args: &[Value]) -> Result<Value, ValueError> {
    channel(args, "colorHexToG", 1)
}

pub fn hex_to_b(args: &[Value]) -> Result<Value, ValueError> {
    channel(args, "colorHexToB", 2)
}

/// Opacity of `"#rrggbboo"`; 0 if the string is too short.
pub fn hex_to_o(args: &[Value]) -> Result<Value, ValueError> {
    channel(args, "colorHexToO", 3)
}

/// `(h in degrees [0, 360), s, v)` of a hex colour. Computed on the byte
/// values so that ratios of bytes (such as `s = 0.5` for `#608040`) are exact.
fn hex_to_hsv(hex: &str) -> (f64, f64, f64) {
    let c = hex_to_rgba(hex);
    let [r, g, b] = [c[0], c[1], c[2]].map(|x| f64::from(x.unwrap_or(0)));
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    let d = max - min;
    let v = max / 255.0;
    let s = if max == 0.0 { 0.0 } else { d / max };
    let h = if d == 0.0 {
        0.0
    } else if max == r {
        let h = 60.0 * ((g - b) / d);
        if h < 0.0 {
            h + 360.0
        } else {
            h
        }
    } else if max == g {
        60.0 * ((b - r) / d + 2.0)
    } else {
        60.0 * ((r - g) / d + 4.0)
    };
    (h, s, v)
}

pub fn hex_to_h(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::Float(hex_to_hsv(str_arg(args, 0, "colorHexToH")?).0))
}

pub fn hex_to_s(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::Float(hex_to_hsv(str_arg(args, 0, "colorHexToS")?).1))
}

pub fn hex_to_v(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::Float(hex_to_hsv(str_arg(args, 0, "colorHexToV")?).2))
}

/// A [0,1] component as a byte: clamped, then rounded (0.5 gives 0x80).
fn byte(x: f64) -> u8 {
    if x.is_nan() {
        0
    } else {
        (x.clamp(0.0, 1.0) * 255.0).round() as u8
    }
}

/// `"#RRGGBB"` (upper case), or `"#RRGGBBOO"` with an opacity.
pub fn rgb_to_hex(r: f64, g: f64, b: f64, opacity: Option<f64>) -> String {
    let mut s = String::with_capacity(9);
    s.push('#');
    for x in [r, g, b].into_iter().chain(opacity) {
        let _ = write!(s, "{:02X}", byte(x));
    }
    s
}

/// HSV (hue in degrees, wrapped into [0, 360); s and v clamped to [0, 1]) to RGB.
fn hsv_to_rgb(h: f64, s: f64, v: f64) -> (f64, f64, f64) {
    let h = if h.is_finite() {
        h.rem_euclid(360.0)
    } else {
        0.0
    };
    let s = if s.is_nan() { 0.0 } else { s.clamp(0.0, 1.0) };
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let c = v * s;
    let hp = h / 60.0;
    let x = c * (1.0 - (hp % 2.0 - 1.0).abs());
    let m = v - c;
    let (r, g, b) = match hp as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    (r + m, g + m, b + m)
}

pub fn rgb_to_hex_fn(args: &[Value]) -> Result<Value, ValueError> {
    let f = "colorRGBToHex";
    let (r, g, b) = (
        float_arg(args, 0, f)?,
        float_arg(args, 1, f)?,
        float_arg(args, 2, f)?,
    );
    Ok(Value::from(rgb_to_hex(r, g, b, None)))
}

pub fn rgbo_to_hex_fn(args: &[Value]) -> Result<Value, ValueError> {
    let f = "colorRGBOToHex";
    let (r, g, b) = (
        float_arg(args, 0, f)?,
        float_arg(args, 1, f)?,
        float_arg(args, 2, f)?,
    );
    let o = float_arg(args, 3, f)?;
    Ok(Value::from(rgb_to_hex(r, g, b, Some(o))))
}

pub fn hsv_to_hex_fn(args: &[Value]) -> Result<Value, ValueError> {
    let f = "colorHSVToHex";
    let (h, s, v) = (
        float_arg(args, 0, f)?,
        float_arg(args, 1, f)?,
        float_arg(args, 2, f)?,
    );
    let (r, g, b) = hsv_to_rgb(h, s, v);
    Ok(Value::from(rgb_to_hex(r, g, b, None)))
}

pub fn hsvo_to_hex_fn(args: &[Value]) -> Result<Value, ValueError> {
    let f = "colorHSVOToHex";
    let (h, s, v) = (
        float_arg(args, 0, f)?,
        float_arg(args, 1, f)?,
        float_arg(args, 2, f)?,
    );
    let o = float_arg(args, 3, f)?;
    let (r, g, b) = hsv_to_rgb(h, s, v);
    Ok(Value::from(rgb_to_hex(r, g, b, Some(o))))
}

/// The presets of `colorRamp` as evenly spaced RGB stops.
///
/// APPROXIMATION: the reference page names the presets but documents no
/// colours, only rendered images. These stops are read off those images (the
/// end colours of each gradient); CityEngine's exact stops are unknown, so
/// results can differ from CityEngine in the low bits of a channel or more.
/// `spectrum` is a hue ramp from magenta (0) over blue, green and yellow to
/// red (1), as its image suggests.
const RAMPS: &[(&str, &[[u8; 3]])] = &[
    ("whiteToBlack", &[[255, 255, 255], [0, 0, 0]]),
    ("yellowToRed", &[[255, 255, 0], [255, 0, 0]]),
    ("greenToRed", &[[0, 255, 0], [255, 255, 0], [255, 0, 0]]),
    ("redToBlue", &[[255, 0, 0], [0, 0, 255]]),
    ("orangeToBlue", &[[255, 216, 0], [0, 0, 255]]),
    ("brownToBlue", &[[168, 88, 32], [32, 136, 152]]),
];

/// `colorRamp(gradient, value)`: the hex colour at `value` (clamped to
/// [0, 1]) of a preset gradient; an error for an unknown preset.
pub fn color_ramp(gradient: &str, value: f64) -> Result<String, ValueError> {
    let t = if value.is_nan() {
        0.0
    } else {
        value.clamp(0.0, 1.0)
    };
    if gradient == "spectrum" {
        let (r, g, b) = hsv_to_rgb(300.0 * (1.0 - t), 1.0, 1.0);
        return Ok(rgb_to_hex(r, g, b, None));
    }
    let stops = RAMPS
        .iter()
        .find(|(name, _)| *name == gradient)
        .map(|(_, stops)| *stops)
        .ok_or_else(|| {
            ValueError::new(format!(
                "colorRamp: unknown gradient {gradient:?} (expected whiteToBlack, greenToRed, \
                 yellowToRed, redToBlue, orangeToBlue, brownToBlue or spectrum)"
            ))
        })?;
    let segments = (stops.len() - 1) as f64;
    let pos = t * segments;
    let i = (pos.floor() as usize).min(stops.len() - 2);
    let u = pos - i as f64;
    let (a, b) = (stops[i], stops[i + 1]);
    let mix = |k: usize| (f64::from(a[k]) + (f64::from(b[k]) - f64::from(a[k])) * u) / 255.0;
    Ok(rgb_to_hex(mix(0), mix(1), mix(2), None))
}

pub fn color_ramp_fn(args: &[Value]) -> Result<Value, ValueError> {
    let gradient = str_arg(args, 0, "colorRamp")?;
    let value = float_arg(args, 1, "colorRamp")?;
    Ok(Value::from(color_ramp(gradient, value)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtins::call;

    fn num(name: &str, hex: &str) -> f64 {
        call(name, &[Value::str(hex)]).unwrap().as_float().unwrap()
    }

    fn hex(name: &str, args: &[f64]) -> String {
        let args: Vec<Value> = args.iter().map(|x| Value::Float(*x)).collect();
        call(name, &args).unwrap().as_str().unwrap().to_string()
    }

    /// celib/colorHexTo*.md. The pages print 16 digits from an older
    /// runtime (0.2509803921568628 for 0x40/255, which is
    /// 0.25098039215686274 in f64), so those values are checked within 1e-15
    /// and exactly as the byte divided by 255.
    #[test]
    fn hex_to_components() {
        for h in ["#4080BF", "#4080BF80"] {
            assert_eq!(num("colorHexToR", h), 64.0 / 255.0);
            assert!((num("colorHexToR", h) - 0.2509803921568628).abs() < 1e-15);
            assert_eq!(num("colorHexToG", h), 128.0 / 255.0);
            assert!((num("colorHexToG", h) - 0.5019607843137256).abs() < 1e-15);
            assert_eq!(num("colorHexToB", h), 191.0 / 255.0);
            assert!((num("colorHexToB", h) - 0.7490196078431374).abs() < 1e-15);
        }
        assert_eq!(num("colorHexToO", "#4080BF80"), 128.0 / 255.0);
        assert_eq!(num("colorHexToO", "#4080BF"), 0.0);
        for h in ["#608040", "#60804080"] {
            assert_eq!(num("colorHexToH", h), 90.0);
            assert_eq!(num("colorHexToS", h), 0.5);
            assert_eq!(num("colorHexToV", h), 128.0 / 255.0);
        }
        assert_eq!(num("colorHexToH", "#FF0000"), 0.0);
        assert_eq!(num("colorHexToH", "#0000FF"), 240.0);
        assert_eq!(num("colorHexToH", "#FF00FF"), 300.0);
        assert_eq!(num("colorHexToS", "#000000"), 0.0);
        assert_eq!(num("colorHexToR", "#ff8000"), 1.0);
        assert_eq!(num("colorHexToR", "#zz"), 0.0);
    }

    /// celib/colorRGBToHex.md, colorRGBOToHex.md, colorHSVToHex.md, colorHSVOToHex.md.
    #[test]
    fn components_to_hex() {
        assert_eq!(hex("colorRGBToHex", &[0.0, 0.5, 1.0]), "#0080FF");
        assert_eq!(hex("colorRGBOToHex", &[0.0, 0.5, 1.0, 0.5]), "#0080FF80");
        assert_eq!(hex("colorHSVToHex", &[90.0, 0.5, 0.5]), "#608040");
        assert_eq!(hex("colorHSVOToHex", &[90.0, 0.5, 0.5, 0.5]), "#60804080");
        // clamping and hue wrapping
        assert_eq!(hex("colorRGBToHex", &[-1.0, 2.0, 0.0]), "#00FF00");
        assert_eq!(hex("colorHSVToHex", &[450.0, 0.5, 0.5]), "#608040");
        assert_eq!(hex("colorHSVToHex", &[-270.0, 0.5, 0.5]), "#608040");
        assert_eq!(hex("colorHSVToHex", &[0.0, 2.0, 1.0]), "#FF0000");
        assert_eq!(hex("colorHSVToHex", &[240.0, 1.0, 1.0]), "#0000FF");
        assert_eq!(hex("colorHSVToHex", &[360.0, 1.0, 1.0]), "#FF0000");
    }

    #[test]
    fn color_ramp_ends_and_errors() {
        assert_eq!(color_ramp("whiteToBlack", 0.0).unwrap(), "#FFFFFF");
        assert_eq!(color_ramp("whiteToBlack", 1.0).unwrap(), "#000000");
        assert_eq!(color_ramp("whiteToBlack", 0.5).unwrap(), "#808080");
        assert_eq!(color_ramp("yellowToRed", 0.0).unwrap(), "#FFFF00");
        assert_eq!(color_ramp("yellowToRed", 2.0).unwrap(), "#FF0000");
        assert_eq!(color_ramp("greenToRed", 0.5).unwrap(), "#FFFF00");
        assert_eq!(color_ramp("spectrum", 1.0).unwrap(), "#FF0000");
        assert_eq!(color_ramp("spectrum", 0.0).unwrap(), "#FF00FF");
        assert!(color_ramp("rainbow", 0.5).is_err());
    }
}
