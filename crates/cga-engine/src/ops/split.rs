//! `split(axis) { size : operations | ... }` (and `{ ... }*`): cuts the
//! current shape along a scope axis into parts whose sizes the pattern gives.
//!
//! The 1D arithmetic (absolute, relative, floating sizes, repeats) is in
//! `split_layout`; this module evaluates the sizes, cuts the geometry once
//! at all part boundaries (closed meshes get caps, see
//! `cga_geometry::split_along_axis`), and runs each part's operations on a
//! new shape whose scope is the part's (`noAdjust`) or the bounding box of
//! its geometry in the parent's orientation (`adjust`, the default).
//!
//! `split(u|v, uvSpace|unitSpace, uvSet) { ... }` splits in texture space
//! instead (see [`uv_split`]).

use std::sync::Arc;

use cga_geometry::{DAffine3, DVec3, Mesh};
use cga_value::Value;

use super::transform::selector;
use crate::derive::{Arg, Interp, RtError, ShapeState, SizeKind};
use crate::expr::{OpCall, RBlock, RBody, RExpr, RPart};
use crate::shape::{Geometry, Shape};
use crate::split_layout::{Placed, Size, SplitLayouter, SplitPattern};

/// Parts thinner than this (in scene units) are not created. Relative
/// splits that recurse forever (the golden-ratio example "stops when the
/// geometry gets too small for a further split") end here.
pub const MIN_PART_SIZE: f64 = 1e-4;

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    let Some(block) = &call.block else {
        return Err(RtError::new("`split` needs a `{ ... }` block", call.span));
    };
    let axis_name = selector(&args[0], &["x", "y", "z", "u", "v"])?;
    if matches!(axis_name, "u" | "v") {
        return uv_split(cx, st, call, args, frame, block, axis_name == "v");
    }
    let axis = match axis_name {
        "x" => 0,
        "y" => 1,
        _ => 2,
    };
    let adjust = match args.get(1) {
        Some(a) => selector(a, &["adjust", "noAdjust"])? == "adjust",
        None => true,
    };
    // The pattern and layout of this split stay in use while its parts'
    // rules run (splits of their own included): each split level takes a
    // scratch of its own from the pool and gives it back.
    let mut scratch = cx.split_scratch.pop().unwrap_or_default();
    let result = split_axis(cx, st, call, frame, block, axis, adjust, &mut scratch);
    cx.split_scratch.push(scratch);
    result
}

/// The room a split fills and empties again: its evaluated pattern, the
/// layout's own scratch and the parts placed. A building's facade makes
/// thousands of splits; allocating these anew for each was five
/// allocations a split.
#[derive(Default)]
pub(crate) struct SplitScratch {
    pattern: SplitPattern,
    layouter: SplitLayouter,
    placed: Vec<Placed>,
}

/// `split` along scope axis `axis`, with `scratch` as its room.
#[allow(clippy::too_many_arguments)]
fn split_axis(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    frame: &[Value],
    block: &RBlock<RBody>,
    axis: usize,
    adjust: bool,
    scratch: &mut SplitScratch,
) -> Result<(), RtError> {
    let SplitScratch {
        pattern,
        layouter,
        placed,
    } = scratch;
    pattern.reset(block.repeat);
    let mut bodies: Vec<&RBody> = Vec::new();
    add_parts(cx, frame, &st.shape, block, pattern, &mut bodies)?;
    let size = st.shape.scope.size[axis];
    layouter
        .layout(pattern, size.abs(), placed)
        .map_err(|e| RtError::new(format!("split: {e}"), call.span))?;
    placed.retain(|p| p.end - p.start >= MIN_PART_SIZE);
    let placed = &placed[..];
    st.has_successor = true;
    if placed.is_empty() {
        return Ok(());
    }
    cx.check_shape_budget(placed.len(), call.span)?;

    let sign = if size < 0.0 { -1.0 } else { 1.0 };
    let pieces = cut_parts(st.shape.geometry.local(), axis, sign, placed);
    let total = placed.len() as f64;
    let last = placed.len() - 1;
    for (k, (part, piece)) in placed.iter().zip(pieces).enumerate() {
        // A split that ends the shape's operations hands the shape itself
        // on to its last part (see `Interp::last_child`).
        let builds = cx.builds_parts(bodies[part.part]);
        let start = sign * part.start;
        let geometry = match builds {
            true => part_geometry(piece, axis, start),
            // Without a model, a part whose rules read nothing of it shows
            // only whether it is empty.
            false => match piece.faces.is_empty() {
                true => crate::shape::Geometry::empty(),
                false => crate::shape::Geometry::unread(),
            },
        };
        let mut child = match st.at_last && k == last {
            true => {
                let mut child = cx.last_child(st, call.span)?;
                child.geometry = geometry;
                child
            }
            false => cx.child_with(&st.shape, geometry, call.span)?,
        };
        if builds {
            place_scope(
                &mut child,
                axis,
                start,
                sign * (part.end - part.start),
                adjust,
            );
        }
        child.split_index = part.index as f64;
        child.split_total = total;
        let mut cst = ShapeState::new(child);
        cx.exec_body(bodies[part.part], frame, &mut cst)?;
        cx.finish(cst);
    }
    Ok(())
}

/// Evaluates the sizes of a split block into `pattern`, in source order;
/// `bodies[k]` is the operations of part `k`.
pub(crate) fn add_parts<'b>(
    cx: &mut Interp,
    frame: &[Value],
    shape: &Shape,
    block: &'b RBlock<RBody>,
    pattern: &mut SplitPattern,
    bodies: &mut Vec<&'b RBody>,
) -> Result<(), RtError> {
    let kind = PartsOf {
        op: "split",
        unlabeled: "a split part needs a size: `size : operations`",
        part: |_, body| body,
    };
    collect_parts(cx, frame, shape, block, pattern, bodies, &kind)
}

/// How [`collect_parts`] reads a block: the operation (for its errors) and
/// what it keeps of each entry, `part(depth, body)`.
pub(crate) struct PartsOf<F> {
    pub op: &'static str,
    /// The error for a part without a size.
    pub unlabeled: &'static str,
    pub part: F,
}

/// Evaluates the sizes of a split-like block (its groups and repeats
/// included) into `pattern`, in source order, and collects what `kind`
/// keeps of each entry: `split`, `splitArea` and `splitAndSetbackPerimeter`
/// read their blocks alike.
pub(crate) fn collect_parts<'b, T, F: Fn(Option<&'b RExpr>, &'b RBody) -> T>(
    cx: &mut Interp,
    frame: &[Value],
    shape: &Shape,
    block: &'b RBlock<RBody>,
    pattern: &mut SplitPattern,
    parts: &mut Vec<T>,
    kind: &PartsOf<F>,
) -> Result<(), RtError> {
    for p in &block.parts {
        match p {
            RPart::Entry {
                head, depth, body, ..
            } => {
                let arg = cx.eval_arg(head, frame, shape)?;
                let x = arg.num()?;
                pattern.push(match arg.kind {
                    SizeKind::Absolute => Size::Absolute(x),
                    SizeKind::Relative => Size::Relative(x),
                    SizeKind::Floating => Size::Floating(x),
                });
                parts.push((kind.part)(depth.as_ref(), body));
            }
            RPart::Group(g) => {
                pattern.open();
                collect_parts(cx, frame, shape, g, pattern, parts, kind)?;
                pattern
                    .close(g.repeat)
                    .map_err(|e| RtError::new(format!("{}: {e}", kind.op), g.span))?;
            }
            RPart::Unlabeled { span, .. } => return Err(RtError::new(kind.unlabeled, *span)),
        }
    }
    Ok(())
}

/// The geometry of each placed part, cut from `mesh` (scope-local) in one
/// pass. Positions along the axis are `sign * distance` from the origin.
fn cut_parts(mesh: &Arc<Mesh>, axis: usize, sign: f64, placed: &[Placed]) -> Vec<Arc<Mesh>> {
    let coord = |d: f64| sign * d;
    let mut cuts: Vec<f64> = placed
        .iter()
        .flat_map(|p| [coord(p.start), coord(p.end)])
        .collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * (1.0 + a.abs()));
    if mesh.faces.is_empty() {
        return placed.iter().map(|_| Arc::new(Mesh::new())).collect();
    }
    // Options, so that a part taking a whole slab leaves `None` behind
    // rather than an empty mesh built for nothing.
    let mut slabs: Vec<Option<Mesh>> = cga_geometry::split_along_axis(mesh, axis, &cuts)
        .into_iter()
        .map(Some)
        .collect();
    // Slab i lies between cuts[i-1] and cuts[i].
    let slab_index = |c: f64| cuts.partition_point(|&x| x < c - 1e-12 * (1.0 + c.abs()));
    let ranges: Vec<(usize, usize)> = placed
        .iter()
        .map(|p| {
            let (a, b) = (coord(p.start), coord(p.end));
            (slab_index(a.min(b)) + 1, slab_index(a.max(b)))
        })
        .collect();
    // A part that is exactly one slab takes it (no copy) unless another
    // part still needs it; parts do not overlap, so that is the rule.
    let mut uses = vec![0u32; slabs.len()];
    for &(first, last) in &ranges {
        for u in uses.iter_mut().take(last + 1).skip(first) {
            *u += 1;
        }
    }
    ranges
        .iter()
        .map(|&(first, last)| {
            let end = last.min(slabs.len().saturating_sub(1));
            if first == last && first <= end {
                uses[first] -= 1;
                let slab = &mut slabs[first];
                let whole = match uses[first] {
                    0 => slab.take(),
                    _ => slab.clone(),
                };
                // Straight into its shared box: a mesh is some 400 bytes,
                // moved once here rather than at every step to its shape.
                return Arc::new(whole.unwrap_or_default());
            }
            let mut out = Mesh::new();
            for k in first..=end {
                uses[k] -= 1;
                if let Some(slab) = &slabs[k] {
                    cga_geometry::transform::merge(&mut out, slab);
                }
            }
            Arc::new(out)
        })
        .collect()
}

/// The geometry of a part cut out at `start` along `axis`: `piece` in the
/// part's scope (whose origin [`place_scope`] moves there). Made before
/// the part's shape, which takes it in place of its parent's
/// (`Interp::child_with`).
pub(crate) fn part_geometry(piece: Arc<Mesh>, axis: usize, start: f64) -> Geometry {
    let mut offset = DVec3::ZERO;
    offset[axis] = start;
    let mut g = Geometry::new(piece);
    g.transform(DAffine3::from_translation(-offset));
    g
}

/// The scope of a part from `start` to `start + size` along `axis` of the
/// scope `child` has (its parent's), its geometry given
/// ([`part_geometry`]); with `adjust`, fitted to that geometry.
pub(crate) fn place_scope(child: &mut Shape, axis: usize, start: f64, size: f64, adjust: bool) {
    let mut offset = DVec3::ZERO;
    offset[axis] = start;
    let axes = child.scope.frame.axes;
    let mut scope = child.scope;
    scope.frame.origin += axes * offset;
    scope.size[axis] = size;
    child.scope = scope;
    if adjust && !child.geometry.is_empty() {
        child.fit_scope(axes);
    }
}

/// `split(u|v, uvSpace|unitSpace, set) { ... }`: the parts are laid out as
/// in the xyz split, between the smallest and the largest value of the
/// coordinate in UV set `set`, and the geometry is cut along the lines where
/// the coordinate takes the part boundaries
/// ([`texturing::cut_along_uv`](super::texturing::cut_along_uv)).
///
/// In `uvSpace` sizes are texture coordinates. In `unitSpace` they are
/// scene units on the surface: the coordinate's range is converted with the
/// surface's average length per unit of the coordinate (area-weighted over
/// the faces, `geometry.du(set, unitSpace)` divided by `geometry.du(set,
/// uvSpace)`), exact for projected and other affine parameterisations.
///
/// Each part's scope is the bounding box of its geometry in the parent's
/// orientation. A shape without texture coordinates in `set` stays as it
/// is, with a warning.
fn uv_split(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
    block: &RBlock<RBody>,
    along_v: bool,
) -> Result<(), RtError> {
    let (Some(space), Some(set)) = (args.get(1), args.get(2)) else {
        return Err(RtError::new(
            "the uv split needs a space and a uv set: `split(u|v, uvSpace|unitSpace, uvSet) { ... }`",
            call.span,
        ));
    };
    let unit_space = selector(space, &["uvSpace", "unitSpace"])? == "unitSpace";
    let set = super::texturing::uv_set(set)?;
    let axis = usize::from(along_v);
    let mesh = st.shape.geometry.local().clone();
    let bounds = cga_geometry::measure::uv_bounds(&mesh, set);
    let scale = if unit_space {
        cga_geometry::measure::uv_unit_scale(&mesh, set).map(|s| s[axis])
    } else {
        Some(1.0)
    };
    let (Some((lo, hi)), Some(scale)) = (bounds, scale.filter(|s| *s > 0.0 && s.is_finite()))
    else {
        cx.warn_once(call.span, || {
            format!("split: the shape has no usable texture coordinates in uv set {set}; it is left unchanged")
        });
        return Ok(());
    };
    let (start, end) = (lo[axis], hi[axis]);

    let mut pattern = SplitPattern::new(block.repeat);
    let mut bodies: Vec<&RBody> = Vec::new();
    add_parts(cx, frame, &st.shape, block, &mut pattern, &mut bodies)?;
    let placed: Vec<Placed> = crate::split_layout::layout(&pattern, (end - start) * scale)
        .map_err(|e| RtError::new(format!("split: {e}"), call.span))?
        .into_iter()
        .filter(|p| p.end - p.start >= MIN_PART_SIZE)
        .collect();
    st.has_successor = true;
    if placed.is_empty() {
        return Ok(());
    }
    cx.check_shape_budget(placed.len(), call.span)?;

    let coord = |d: f64| start + d / scale;
    let mut cuts: Vec<f64> = placed
        .iter()
        .flat_map(|p| [coord(p.start), coord(p.end)])
        .collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * (1.0 + a.abs()));
    let mut slabs = super::texturing::cut_along_uv(&mesh, set, axis, &cuts);
    // Slab i lies between cuts[i-1] and cuts[i].
    let slab_index = |c: f64| cuts.partition_point(|&x| x < c - 1e-12 * (1.0 + c.abs()));
    let axes = st.shape.scope.frame.axes;
    let total = placed.len() as f64;
    let ranges: Vec<(usize, usize)> = placed
        .iter()
        .map(|p| (slab_index(coord(p.start)) + 1, slab_index(coord(p.end))))
        .collect();
    let mut uses = vec![0u32; slabs.len()];
    for &(first, last) in &ranges {
        for u in uses.iter_mut().take(last + 1).skip(first) {
            *u += 1;
        }
    }
    for (part, &(first, last)) in placed.iter().zip(&ranges) {
        let mut piece = Mesh::new();
        for (slab, u) in slabs.iter_mut().zip(&mut uses).take(last + 1).skip(first) {
            *u -= 1;
            if piece.faces.is_empty() {
                // The last part that needs a slab takes it; parts do not
                // overlap, so that is the only one.
                piece = if *u == 0 {
                    std::mem::take(slab)
                } else {
                    slab.clone()
                };
            } else {
                cga_geometry::transform::merge(&mut piece, slab);
            }
        }
        let mut child = cx.child(&st.shape, call.span)?;
        let empty = piece.faces.is_empty();
        child.set_local_mesh(piece);
        if !empty {
            child.fit_scope(axes);
        }
        child.split_index = part.index as f64;
        child.split_total = total;
        let mut cst = ShapeState::new(child);
        cx.exec_body(bodies[part.part], frame, &mut cst)?;
        cx.finish(cst);
    }
    Ok(())
}
