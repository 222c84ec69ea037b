//! `splitArea(axis) { area : operations | ... }` (and `{ ... }*`): cuts the
//! current shape's geometry with planes perpendicular to a scope axis into
//! parts of given areas.
//!
//! The size arithmetic is `split`'s (`split_layout`) with areas instead of
//! lengths: the pattern is laid out on `L` = the geometry's area, so every
//! part gets an interval `[A0, A1]` of cumulative area (`'r` is `r` times
//! the area, `~w` shares what the fixed areas leave, repeats and nested
//! groups as in `split`; sums below the whole leave the rest unused, a part
//! reaching beyond it is cut at the whole and later ones are not created).
//! `cga_geometry::AreaProfile` then gives, in closed
//! form, the position along the axis where the area on the low side reaches
//! each `A`, and the geometry is cut there once. Part `k`'s geometry is the
//! slab between its two cuts (on lots with holes or concave lots it may
//! consist of several pieces); its scope is that slab (`noAdjust`) or the
//! bounding box of its geometry in the parent's orientation (`adjust`, the
//! default), as in `split`.
//!
//! Parts follow the axis from the scope's origin: along +axis, or along
//! -axis when the scope's size on it is negative, as `split` does.
//! `split.index` / `split.total` count the created parts (parts below
//! [`MIN_PART_AREA`] are not created and not counted).
//!
//! The areas are exact on planar geometry, also with several faces not in
//! one plane (each face is measured in its own plane). Faces bent out of
//! their plane are handled by `AreaProfile::cut_positions` (every part but
//! the last measures exactly; areas of bent faces are not additive). Bent
//! or closed geometry, and geometry perpendicular to the axis, get a
//! warning and a best effort, never an error.

use std::cell::RefCell;

use cga_geometry::{split_by_parallel_planes, AreaProfile, DVec3, Mesh};
use cga_value::Value;

use super::split::{add_parts, part_geometry, place_scope};
use super::transform::selector;
use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::{OpCall, RBody};
use crate::split_layout::{Placed, SplitPattern};

/// Parts with less area than this (in square scene units) are not created,
/// the area counterpart of `split::MIN_PART_SIZE` (its square). Relative
/// splits that recurse forever end here.
pub const MIN_PART_AREA: f64 = 1e-8;

/// Scratch reused by all `splitArea` calls of a thread: the profile's
/// buffers and the area bounds.
#[derive(Default)]
struct Scratch {
    profile: AreaProfile,
    bounds: Vec<f64>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// One part to create: its entry in the pattern, and its geometry's slab:
/// between `positions[slab - 1]` and `positions[slab]`.
struct Part {
    body: usize,
    slab: usize,
}

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    let Some(block) = &call.block else {
        return Err(RtError::new(
            "`splitArea` needs a `{ ... }` block",
            call.span,
        ));
    };
    let axis = match selector(&args[0], &["x", "y", "z"])? {
        "x" => 0,
        "y" => 1,
        _ => 2,
    };
    let adjust = match args.get(1) {
        Some(a) => selector(a, &["adjust", "noAdjust"])? == "adjust",
        None => true,
    };

    let mut pattern = SplitPattern::new(block.repeat);
    let mut bodies: Vec<&RBody> = Vec::new();
    add_parts(cx, frame, &st.shape, block, &mut pattern, &mut bodies)?;
    st.has_successor = true;

    let size = st.shape.scope.size[axis];
    let sign = if size < 0.0 { -1.0 } else { 1.0 };
    let mut dir = DVec3::ZERO;
    dir[axis] = sign;
    let mesh = st.shape.geometry.local().clone();

    // Everything that needs the scratch space happens here; the parts'
    // operations (which may split areas again) run after it is released.
    let plan = SCRATCH
        .with(|scratch| plan(&mut scratch.borrow_mut(), &mesh, dir, size.abs(), &pattern))
        .map_err(|e| RtError::new(e, call.span))?;
    if let Some(w) = plan.warning {
        cx.warn_once(call.span, || w);
    }
    if plan.parts.is_empty() {
        return Ok(());
    }

    // Slab k of the cut lies between `cuts[k - 1]` and `cuts[k]`.
    let cuts = &plan.positions[plan.first_cut..plan.end_cut];
    let mut slabs = split_by_parallel_planes(&mesh, dir, cuts);
    // splitArea does not support component tags: CityEngine clears them
    // (cga_componentTags.md, "Operations that clear all tags").
    slabs.iter_mut().for_each(cga_geometry::tags::clear_tags);
    let total = plan.parts.len() as f64;
    for (index, part) in plan.parts.iter().enumerate() {
        let (start, end) = (plan.positions[part.slab - 1], plan.positions[part.slab]);
        let piece = std::sync::Arc::new(std::mem::take(&mut slabs[part.slab - plan.first_cut]));
        let geometry = part_geometry(piece, axis, sign * start);
        let mut child = cx.child_with(&st.shape, geometry, call.span)?;
        place_scope(&mut child, axis, sign * start, sign * (end - start), adjust);
        child.split_index = index as f64;
        child.split_total = total;
        let mut cst = ShapeState::new(child);
        cx.exec_body(bodies[part.body], frame, &mut cst)?;
        cx.finish(cst);
    }
    Ok(())
}

/// What a `splitArea` creates, before any part runs.
struct Plan {
    parts: Vec<Part>,
    /// Position along the split direction of every part boundary (the
    /// scope-local frame's coordinate times the direction's sign).
    positions: Vec<f64>,
    /// The geometry is cut at `positions[first_cut..end_cut]`: not where the
    /// first part starts at area 0 nor where the last ends at the whole area.
    /// The geometry beyond belongs to that part anyway, and a face lying in
    /// such a plane (a lot split along its own normal) stays in the part
    /// instead of being cut off to the side nobody takes.
    first_cut: usize,
    end_cut: usize,
    warning: Option<String>,
}

/// Lays the pattern out on the geometry's area and finds the cut positions
/// (along `dir`, in the scope-local frame; the scope spans `[0, extent]`
/// along `dir`).
fn plan(
    scratch: &mut Scratch,
    mesh: &Mesh,
    dir: DVec3,
    extent: f64,
    pattern: &SplitPattern,
) -> Result<Plan, String> {
    let Scratch { profile, bounds } = scratch;
    profile.build(mesh, dir);
    let area = profile.total();
    let flat = profile.flatness();
    let warning = if !mesh.faces.is_empty() && area <= 0.0 {
        Some("splitArea: the geometry has no area; no part is created".to_string())
    } else if flat.is_bent() {
        Some(
            "splitArea works on planar geometry; this geometry is not planar (or is a volume), \
             so the parts' areas are approximate"
                .to_string(),
        )
    } else if !flat.is_nearly_planar() {
        Some(format!(
            "splitArea: the geometry (area {}) lies in a plane perpendicular to the split axis \
             and cannot be divided along it",
            cga_value::format::format_float(flat.area),
        ))
    } else {
        None
    };
    let mut plan = Plan {
        parts: Vec::new(),
        positions: Vec::new(),
        first_cut: 0,
        end_cut: 0,
        warning,
    };

    let placed: Vec<Placed> = crate::split_layout::layout(pattern, area)
        .map_err(|e| format!("splitArea: {e}"))?
        .into_iter()
        .filter(|p| p.end - p.start >= MIN_PART_AREA)
        .collect();
    if placed.is_empty() {
        return Ok(plan);
    }

    // Cumulative area at every part boundary, each once: consecutive parts
    // share theirs (the layout makes a part's end bit for bit the next
    // part's start), parts after a dropped one start a new slab.
    bounds.clear();
    plan.parts.reserve(placed.len());
    for p in &placed {
        if bounds.last() != Some(&p.start) {
            bounds.push(p.start);
        }
        bounds.push(p.end);
        plan.parts.push(Part {
            body: p.part,
            slab: bounds.len() - 1,
        });
    }
    profile.cut_positions(mesh, bounds, &mut plan.positions);
    // A part starting at area 0 starts at the scope's start, one ending at
    // the whole area ends at the scope's end (or the geometry's, if it lies
    // outside): with `noAdjust` the parts' scopes then fill the parent's.
    let (lo, hi) = profile.range().unwrap_or((0.0, extent));
    plan.first_cut = usize::from(bounds[0] <= 0.0);
    if plan.first_cut == 1 {
        plan.positions[0] = lo.min(0.0);
    }
    plan.end_cut = bounds.len();
    if bounds[bounds.len() - 1] >= area {
        plan.end_cut -= 1;
        plan.positions[bounds.len() - 1] = hi.max(extent);
    }
    Ok(plan)
}
