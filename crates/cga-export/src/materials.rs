//! The table of distinct materials of a model, in order of first appearance.
//!
//! Geometry is merged per material, so every face asks "which output material
//! is this?". Materials are compared by value: two shapes that set the same
//! colour, textures and so on share one output material even though their
//! `Material` values were built separately.

use std::collections::hash_map::Entry;
use std::collections::HashSet;
use std::hash::{Hash, Hasher};

use cga_geometry::Material;

use crate::hash::FastMap;

/// A material as a hash map key. Equality is by value with two twists that
/// keep the table small and well-defined: `0.0` and `-0.0` are the same, and
/// so are any two NaNs (with IEEE equality a NaN material would never match
/// itself and would create a new output material for every face).
struct Key(Material);

/// Bits of an `f64` under [`Key`]'s equality.
fn bits(x: f64) -> u64 {
    if x == 0.0 {
        0
    } else if x.is_nan() {
        f64::NAN.to_bits()
    } else {
        x.to_bits()
    }
}

/// Whether two numbers are the same under [`Key`]'s equality.
fn same(a: f64, b: f64) -> bool {
    bits(a) == bits(b)
}

fn same3(a: &[f64; 3], b: &[f64; 3]) -> bool {
    a.iter().zip(b).all(|(&x, &y)| same(x, y))
}

impl Hash for Key {
    /// Hashes the fields that usually tell materials apart; equality checks
    /// the rest. Cheap, because every face of a new mesh looks up its
    /// material.
    fn hash<H: Hasher>(&self, state: &mut H) {
        let m = &self.0;
        m.name.hash(state);
        m.maps[0].path.hash(state);
        for x in m.color {
            state.write_u64(bits(x));
        }
        state.write_u64(bits(m.opacity));
    }
}

impl PartialEq for Key {
    fn eq(&self, other: &Key) -> bool {
        same_material(&self.0, &other.0)
    }
}

/// Equality by value, as [`Key`] defines it; the most discriminating fields
/// are compared first.
pub(crate) fn same_material(a: &Material, b: &Material) -> bool {
    same3(&a.color, &b.color)
        && same(a.opacity, b.opacity)
        && a.name == b.name
        && a.maps.iter().zip(&b.maps).all(|(x, y)| {
            x.path == y.path
                && same(x.su, y.su)
                && same(x.sv, y.sv)
                && same(x.tu, y.tu)
                && same(x.tv, y.tv)
                && same(x.rw, y.rw)
        })
        && same3(&a.ambient, &b.ambient)
        && same3(&a.specular, &b.specular)
        && same3(&a.emissive, &b.emissive)
        && same(a.reflectivity, b.reflectivity)
        && same(a.shininess, b.shininess)
        && same(a.bump_value, b.bump_value)
        && same(a.metallic, b.metallic)
        && same(a.roughness, b.roughness)
        && same(a.opacitymap_cutoff, b.opacitymap_cutoff)
        && a.double_sided == b.double_sided
        && a.shader == b.shader
        && a.opacitymap_mode == b.opacitymap_mode
}

impl Eq for Key {}

/// Distinct materials with their output names, indexed by material id.
#[derive(Default)]
pub(crate) struct MaterialTable {
    ids: FastMap<Key, u32>,
    /// Material by id (a clone; the input meshes are not kept).
    materials: Vec<Material>,
    /// Output name by id: unique, derived from `Material::name`.
    names: Vec<String>,
    taken: HashSet<String>,
    /// The id returned last: consecutive shapes mostly share a material,
    /// and comparing with it avoids cloning and hashing.
    last: Option<u32>,
}

impl MaterialTable {
    /// The id of `m`, and whether it was new.
    pub(crate) fn intern(&mut self, m: &Material) -> (u32, bool) {
        if let Some(last) = self.last {
            if same_material(&self.materials[last as usize], m) {
                return (last, false);
            }
        }
        // The lookup needs an owned key because `Key` wraps a value; cloning
        // a material is cheap (its strings are `Arc`s).
        let (id, new) = match self.ids.entry(Key(m.clone())) {
            Entry::Occupied(e) => (*e.get(), false),
            Entry::Vacant(e) => {
                let id = self.materials.len() as u32;
                e.insert(id);
                self.materials.push(m.clone());
                let name = if m.name.trim().is_empty() {
                    unique_name(&derived_name(m), &mut self.taken)
                } else {
                    unique_name(&m.name, &mut self.taken)
                };
                self.names.push(name);
                (id, true)
            }
        };
        self.last = Some(id);
        (id, new)
    }

    /// The materials by id, leaving the table empty.
    pub(crate) fn take_materials(&mut self) -> Vec<Material> {
        let materials = std::mem::take(&mut self.materials);
        *self = MaterialTable::default();
        materials
    }

    pub(crate) fn get(&self, id: u32) -> &Material {
        &self.materials[id as usize]
    }

    pub(crate) fn name(&self, id: u32) -> &str {
        &self.names[id as usize]
    }
}

/// The name of a material whose `material.name` is empty, from what it
/// looks like: its colour map's file name without extension (`bricks` for
/// `facade/bricks.jpg`), else its colour (`color_cc8844`), so that a user
/// picking materials in a modelling program sees what each is.
fn derived_name(m: &Material) -> String {
    let map = m.maps[0].path.as_ref();
    let file = map.rsplit(['/', '\\', ':']).next().unwrap_or_default();
    let stem = match file.rsplit_once('.') {
        Some((stem, _)) if !stem.is_empty() => stem,
        _ => file,
    };
    if !stem.trim().is_empty() {
        return stem.to_string();
    }
    let [r, g, b] = m.color.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
    format!("color_{r:02x}{g:02x}{b:02x}")
}

/// A name usable in an MTL file (one token, no whitespace or control
/// characters) that no earlier material of the model has: `brick`, then
/// `brick_2`, `brick_3`, ... Names follow the order of first appearance, so
/// the same model always gets the same names.
fn unique_name(wanted: &str, taken: &mut HashSet<String>) -> String {
    let mut base: String = wanted
        .trim()
        .chars()
        .map(|c| {
            if c.is_whitespace() || c.is_control() {
                '_'
            } else {
                c
            }
        })
        .collect();
    if base.is_empty() {
        base.push_str("material");
    }
    let mut name = base.clone();
    let mut n = 2;
    while taken.contains(&name) {
        name = format!("{base}_{n}");
        n += 1;
    }
    taken.insert(name.clone());
    name
}

/// Converts a CGA colour component (non-linear, as the colour pickers that
/// produce it) to the linear value glTF colour factors hold, as CityEngine's
/// runtime writes it: a pure 2.2 power curve, not the piecewise sRGB curve
/// (measured on its GLB: `#cccccc` gives 0.612, where sRGB gives 0.604), so
/// that a model looks the same from both engines.
pub(crate) fn color_to_linear(c: f64) -> f64 {
    c.clamp(0.0, 1.0).powf(2.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_values_share_an_id() {
        let mut t = MaterialTable::default();
        let a = Material {
            color: [0.5, 0.25, 0.0],
            ..Material::default()
        };
        let b = Material {
            color: [0.5, 0.25, -0.0],
            ..Material::default()
        };
        assert_eq!(t.intern(&a), (0, true));
        assert_eq!(t.intern(&b), (0, false));
        let c = Material {
            opacity: 0.5,
            ..a.clone()
        };
        assert_eq!(t.intern(&c), (1, true));
    }

    #[test]
    fn nan_material_matches_itself() {
        let mut t = MaterialTable::default();
        let m = Material {
            roughness: f64::NAN,
            ..Material::default()
        };
        assert_eq!(t.intern(&m), (0, true));
        assert_eq!(t.intern(&m), (0, false));
    }

    #[test]
    fn names_are_unique_and_tokens() {
        let mut t = MaterialTable::default();
        let named = |name: &str, r: f64| Material {
            name: name.into(),
            color: [r, 1.0, 1.0],
            ..Material::default()
        };
        t.intern(&named("red brick", 0.1));
        t.intern(&named("red brick", 0.2));
        t.intern(&named("", 0.3));
        t.intern(&named("red_brick_2", 0.4));
        assert_eq!(t.name(0), "red_brick");
        assert_eq!(t.name(1), "red_brick_2");
        // Unnamed: by its colour (0.3 * 255 = 76.5, rounded to 77 = 0x4d).
        assert_eq!(t.name(2), "color_4dffff");
        assert_eq!(t.name(3), "red_brick_2_2");
    }

    #[test]
    fn unnamed_materials_are_named_by_their_colour_map() {
        let mut t = MaterialTable::default();
        let mapped = |path: &str, r: f64| {
            let mut m = Material {
                color: [r, 1.0, 1.0],
                ..Material::default()
            };
            m.maps[0].path = path.into();
            m
        };
        t.intern(&mapped("facade/bricks.jpg", 1.0));
        t.intern(&mapped("other/bricks.png", 1.0));
        t.intern(&mapped("builtin:uvtest.png", 1.0));
        t.intern(&mapped("C:\\tex\\roof tiles.jpg", 1.0));
        t.intern(&mapped("", 0.0));
        assert_eq!(t.name(0), "bricks");
        assert_eq!(t.name(1), "bricks_2");
        assert_eq!(t.name(2), "uvtest");
        assert_eq!(t.name(3), "roof_tiles");
        assert_eq!(t.name(4), "color_00ffff");
    }

    #[test]
    fn colours_follow_cityengines_power_curve() {
        assert_eq!(color_to_linear(0.0), 0.0);
        assert_eq!(color_to_linear(1.0), 1.0);
        // CityEngine's GLB: #cccccc gives 0.612.
        assert!((color_to_linear(0.8) - 0.612).abs() < 5e-4);
        // Candler's bricks (#fcefe2): 0.974, 0.867, 0.767.
        let bricks = [252.0, 239.0, 226.0].map(|c: f64| color_to_linear(c / 255.0));
        for (got, want) in bricks.iter().zip([0.974, 0.867, 0.767]) {
            assert!((got - want).abs() < 5e-4, "{got} vs {want}");
        }
        assert_eq!(color_to_linear(-0.5), 0.0);
        assert_eq!(color_to_linear(2.0), 1.0);
    }
}
