//! What generating a lot gives: plain data.

use std::sync::Arc;

pub use cga_export::{PlainMesh, PlainModel};
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
    /// ([`Target::Meshes`](crate::Target::Meshes)); empty otherwise.
    pub model: PlainModel,
    /// Where each leaf of `model` comes from, by the leaf numbers of
    /// [`PlainMesh::triangle_leaf`]; empty unless meshes were asked for.
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
    /// Where the triangle `triangle` of `model.meshes[mesh]` comes from.
    pub fn provenance(&self, rules: &Rules, mesh: usize, triangle: usize) -> Option<Provenance> {
        let leaf = *self.model.meshes.get(mesh)?.triangle_leaf.get(triangle)?;
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
