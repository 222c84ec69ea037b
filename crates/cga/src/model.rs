//! What generating a lot gives: plain data.

use std::sync::Arc;

pub use cga_export::{DrawFaces, DrawMesh, DrawModel, DrawNormals, PlainMesh, PlainModel};
pub use cga_geometry::Material;
use cga_value::Value;

use crate::diagnostics::{Diagnostic, Location};
use crate::rules::{RuleRef, Rules};

/// The outcome of one lot.
#[derive(Clone, Debug, Default)]
pub struct LotResult {
    /// The lot's index among the lots of the generation.
    pub index: usize,
    /// The lot's name (file and face, feature id, `rect 20x30`).
    pub name: String,
    /// Triangles by material, when meshes were asked for
    /// ([`Target::Meshes`](crate::Target::Meshes), or positions alone:
    /// [`Target::Positions`](crate::Target::Positions)); empty otherwise.
    pub model: PlainModel,
    /// Triangles by material as a viewer draws them, when asked for
    /// ([`Target::Drawing`](crate::Target::Drawing)); empty otherwise.
    pub drawing: DrawModel,
    /// Where each leaf of `model` (or `drawing`) comes from, by the leaf
    /// numbers of [`PlainMesh::triangle_leaf`]; empty unless meshes were
    /// asked for.
    pub leaves: Vec<LeafOrigin>,
    /// Leaf shapes made (also when no meshes were kept).
    pub leaf_count: usize,
    /// The lines of `print()`, in derivation order.
    pub prints: Vec<String>,
    /// The values of `report()`, in derivation order.
    pub reports: Vec<(String, Value)>,
    pub warnings: Vec<Diagnostic>,
    /// The error that stopped the lot part way (what was made before it is
    /// kept), if one did.
    pub error: Option<Diagnostic>,
    /// Shapes created.
    pub shapes: usize,
    /// Triangles of the lot written to the model file, when the lots were
    /// generated into one ([`Target::Writer`](crate::Target::Writer),
    /// [`Target::PerLot`](crate::Target::PerLot)): the triangles its plain
    /// meshes would have, an instanced asset counted once per placement.
    /// `None` when nothing was written.
    pub triangles_written: Option<u64>,
}

/// The rule and shape a leaf comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LeafOrigin {
    /// The rule whose application made the leaf; `None` for a lot that no
    /// rule changed.
    pub rule: Option<RuleRef>,
    /// The shape's name: the rule's, or the leaf's (`Window.` gives
    /// `Window`).
    pub shape: Arc<str>,
}

/// A leaf's origin as a person reads it.
#[derive(Clone, Debug, PartialEq)]
pub struct Provenance {
    /// The rule's name (with its import prefix: `imp.Facade`).
    pub rule: Option<String>,
    pub shape: Arc<str>,
    /// Where the rule is defined.
    pub location: Option<Location>,
}

impl LotResult {
    /// Where the triangle `triangle` of `model.meshes[mesh]` (or, when
    /// the meshes kept were to draw, of `drawing.meshes[mesh]`) comes
    /// from.
    pub fn provenance(&self, rules: &Rules, mesh: usize, triangle: usize) -> Option<Provenance> {
        let leaves = match self.model.meshes.get(mesh) {
            Some(m) => &m.triangle_leaf,
            None => &self.drawing.meshes.get(mesh)?.triangle_leaf,
        };
        let leaf = *leaves.get(triangle)?;
        let origin = self.leaves.get(leaf as usize)?;
        Some(rules.provenance(origin))
    }
}

impl Rules {
    /// A leaf's origin with its rule's name and place.
    pub fn provenance(&self, origin: &LeafOrigin) -> Provenance {
        let info = origin.rule.map(|r| self.rule(r));
        Provenance {
            rule: info.as_ref().map(|i| {
                if i.prefix.is_empty() {
                    i.name.clone()
                } else {
                    format!("{}.{}", i.prefix, i.name)
                }
            }),
            shape: origin.shape.clone(),
            location: info.and_then(|i| i.location),
        }
    }
}

/// What a generation of many lots did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    pub lots: usize,
    /// Lots stopped by an error (rules or limits).
    pub failed: usize,
    pub shapes: usize,
    pub leaves: usize,
    /// Seconds from the start until every lot was derived.
    pub derived_after: f64,
}

/// Adds plain meshes (made by [`Rules::generate`] or a host's own code:
/// the Python package writes the models its users kept) to a model file:
/// each triangle is written as a face with its vertices' normals and
/// texture coordinates and its mesh's material. Meshes that name a
/// material the model does not have, or indices out of range, are an
/// [`Error::Export`](crate::Error::Export).
pub fn write_plain(
    writer: &mut cga_export::ModelWriter,
    model: &PlainModel,
) -> Result<(), crate::Error> {
    use cga_geometry::{DVec2, DVec3, Mesh};
    let bad = |why: String| crate::Error::Export(cga_export::ExportError::InvalidMesh(why));
    let mut mesh = Mesh::new();
    mesh.materials = model.materials.clone().into();
    if mesh.materials.is_empty() {
        mesh.materials = vec![Material::default()].into();
    }
    let corners: usize = model.meshes.iter().map(|m| m.indices.len() * 3).sum();
    mesh.uvs[0] = Some(Vec::with_capacity(corners));
    mesh.normals = Some(Vec::with_capacity(corners));
    mesh.reserve(corners);
    for (k, m) in model.meshes.iter().enumerate() {
        if m.material >= mesh.materials.len() {
            return Err(bad(format!(
                "mesh {k} names material {} of {}",
                m.material,
                mesh.materials.len()
            )));
        }
        let n = m.positions.len();
        if m.normals.len() != n || m.uvs.len() != n {
            return Err(bad(format!(
                "mesh {k} has {n} positions, {} normals and {} texture coordinates",
                m.normals.len(),
                m.uvs.len()
            )));
        }
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(m.positions.iter().map(|p| DVec3::from_array(*p)));
        for t in &m.indices {
            if t.iter().any(|&i| i as usize >= n) {
                return Err(bad(format!(
                    "mesh {k} has a triangle {t:?} past its {n} vertices"
                )));
            }
            let idx = [base + t[0], base + t[1], base + t[2]];
            mesh.add_face(&[&idx], m.material as u32);
            let start = mesh.corners.len() - 3;
            for (c, &i) in t.iter().enumerate() {
                let i = i as usize;
                if let Some(uvs) = &mut mesh.uvs[0] {
                    uvs[start + c] = DVec2::from_array(m.uvs[i]);
                }
                if let Some(normals) = &mut mesh.normals {
                    normals[start + c] = DVec3::from_array(m.normals[i]);
                }
            }
        }
    }
    writer.add_mesh(&mesh).map_err(crate::Error::Export)
}
