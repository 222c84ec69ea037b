//! The footprint toolkit: `offset`, `setback`, `setbackPerEdge`,
//! `setbackToArea`, `shapeL`/`shapeU`/`shapeO`, `splitAndSetbackPerimeter`,
//! `innerRectangle` (and the deprecated `innerRect`), `envelope`, `taper`
//! and `footprint`.
//!
//! The geometry lives in `cga_geometry` (`setback`, `inner_rect`,
//! `envelope`, `perimeter`, `footprint`); this module reads the arguments,
//! selects the edges (with `comp(fe)`'s selectors, see
//! `ops::comp::FaceEdgeSelection`) and makes the shapes. Polygons are
//! handled in the current shape's scope-local coordinates, which are
//! metric; texture coordinates are carried over from the faces they were
//! cut from (`cga_geometry::uv_carry`).
//!
//! Shapes created here (setback strips and remainders, L/U/O shapes, inner
//! rectangles, perimeter sections) keep the current shape's pivot and scope
//! orientation; their scope is the bounding box of their geometry in that
//! orientation, as `split` does with `adjust`. `offset`, `envelope`,
//! `taper` and `footprint` change the current shape: `offset` and
//! `envelope` keep the scope orientation and fit its size, `taper` sets the
//! scope as the roof operations do (y along the face normal, x the old x
//! projected), `footprint` keeps the scope and sets sy to 0.
//!
//! Degenerate polygons (collinear points, zero area, self-intersections
//! the straight skeleton cannot handle) never stop the derivation: the
//! operation warns and keeps the face whole where it can (as the remainder
//! of a setback, the inside of an offset).

use cga_geometry::setback::{Offset, OffsetFace};
use cga_geometry::{measure, DVec2, DVec3, Mesh};
use cga_syntax::ast::BlockOp;
use cga_syntax::Span;
use cga_value::Value;

use super::comp::FaceEdgeSelection;
use super::transform::selector;
use super::FootprintOp;
use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::{OpCall, RBlock, RBody, RExpr, RExprKind, RPart};
use crate::selectors::{quadrant_of, Frames, Quadrant};
use crate::shape::Shape;
use crate::split_layout::{Placed, SplitPattern};
use cga_geometry::perimeter;

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    op: FootprintOp,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    match op {
        FootprintOp::Offset => offset(cx, st, call, args),
        FootprintOp::Setback | FootprintOp::SetbackPerEdge | FootprintOp::SetbackToArea => {
            setback(cx, st, op, call, args, frame)
        }
        FootprintOp::ShapeL | FootprintOp::ShapeU | FootprintOp::ShapeO => {
            shape_luo(cx, st, op, call, args, frame)
        }
        FootprintOp::InnerRectangle => inner_rectangle(cx, st, call, args, frame),
        FootprintOp::InnerRect => inner_rect(st),
        FootprintOp::Envelope => envelope(cx, st, call, args),
        FootprintOp::Taper => taper(st, args),
        FootprintOp::Footprint => footprint(st),
        FootprintOp::SplitAndSetbackPerimeter => perimeter(cx, st, call, args, frame),
    }
}

// ----- shared helpers -----

/// One entry of a setback-like block.
pub(crate) struct Entry<'a> {
    pub head: &'a RExpr,
    pub op: BlockOp,
    pub body: &'a RBody,
    pub span: Span,
}

pub(crate) fn entries<'a>(
    block: Option<&'a RBlock<RBody>>,
    name: &str,
    span: Span,
) -> Result<Vec<Entry<'a>>, RtError> {
    let Some(block) = block else {
        return Err(RtError::new(
            format!("`{name}` needs a `{{ selector : operations | ... }}` block"),
            span,
        ));
    };
    let mut out = Vec::with_capacity(block.parts.len());
    for p in &block.parts {
        match p {
            RPart::Entry {
                head,
                op,
                body,
                span,
                ..
            } => out.push(Entry {
                head,
                op: *op,
                body,
                span: *span,
            }),
            RPart::Group(g) => {
                return Err(RtError::new(
                    format!("a `{name}` block has no groups: write `selector : operations | ...`"),
                    g.span,
                ))
            }
            RPart::Unlabeled { span, .. } => {
                return Err(RtError::new(
                    format!("a `{name}` block entry needs a selector: `selector : operations`"),
                    *span,
                ))
            }
        }
    }
    Ok(out)
}

/// The keyword a head names, if it is a plain keyword (`remainder`, `shape`).
pub(crate) fn keyword(head: &RExpr) -> Option<&str> {
    match &head.kind {
        RExprKind::Const(Value::Str(s)) => Some(s),
        _ => None,
    }
}

/// A mesh of some faces of `src`, with its materials and per-corner
/// attributes.
pub(crate) fn sub_mesh(src: &Mesh, faces: &[usize]) -> Mesh {
    let mut out = Mesh::new();
    out.share_slots(src);
    if src.edge_tags.is_some() {
        out.edge_tags = Some(Vec::new());
    }
    if src.vertex_tags.is_some() {
        out.vertex_tags = Some(Vec::new());
    }
    for (k, set) in src.uvs.iter().enumerate() {
        if set.is_some() {
            out.uvs[k] = Some(Vec::new());
        }
    }
    if src.normals.is_some() {
        out.normals = Some(Vec::new());
    }
    for &f in faces {
        let mut ids: Vec<Vec<u32>> = Vec::new();
        let first = out.corners.len();
        for &l in src.face_loops(f) {
            let s = out.positions.len() as u32;
            out.positions.extend(src.loop_points(l));
            ids.push((s..s + l.len).collect());
        }
        let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
        let nf = out.add_face(&refs, src.faces[f].material);
        out.faces[nf].group = src.faces[f].group;
        out.faces[nf].tags = src.faces[f].tags;
        let corners = src
            .face_loops(f)
            .iter()
            .flat_map(|&l| src.loop_corners(l))
            .enumerate();
        for (i, c) in corners {
            for (k, set) in out.uvs.iter_mut().enumerate() {
                if let (Some(dst), Some(s)) = (set.as_mut(), src.uvs[k].as_ref()) {
                    dst[first + i] = s[c];
                }
            }
            if let (Some(dst), Some(s)) = (out.normals.as_mut(), src.normals.as_ref()) {
                dst[first + i] = s[c];
            }
            if let Some(dst) = out.edge_tags.as_mut() {
                dst[first + i] = src.edge_tag_index(c);
            }
            if let Some(dst) = out.vertex_tags.as_mut() {
                dst[first + i] = src.vertex_tag_index(c);
            }
        }
    }
    out
}

/// Makes shapes of the polygons `faces` of `src` (scope-local) for one
/// entry: one shape per face (`:`), or one of all (`=`, `=:`). Each shape
/// keeps the parent's pivot and scope orientation, its scope fitted.
#[allow(clippy::too_many_arguments)]
pub(crate) fn spawn(
    cx: &mut Interp,
    st: &mut ShapeState,
    frame: &[Value],
    src: &Mesh,
    faces: &[usize],
    op: BlockOp,
    body: &RBody,
    span: Span,
) -> Result<(), RtError> {
    st.has_successor = true;
    if faces.is_empty() {
        return Ok(());
    }
    let sets: Vec<Vec<usize>> = match op {
        BlockOp::Colon => faces.iter().map(|&f| vec![f]).collect(),
        _ => vec![faces.to_vec()],
    };
    for set in sets {
        let mut child = cx.child(&st.shape, span)?;
        place(&mut child, sub_mesh(src, &set));
        let mut cst = ShapeState::new(child);
        cx.exec_body(body, frame, &mut cst)?;
        cx.finish(cst);
    }
    Ok(())
}

/// Gives `shape` the geometry `mesh` (scope-local) and fits the scope to
/// it in the same orientation.
pub(crate) fn place(shape: &mut Shape, mesh: Mesh) {
    let empty = mesh.faces.is_empty();
    shape.set_local_mesh(mesh);
    if !empty {
        let axes = shape.scope.frame.axes;
        shape.fit_scope(axes);
    }
}

/// Number of face edges (every edge of every loop of every face).
pub(crate) fn face_edge_count(mesh: &Mesh) -> usize {
    (0..mesh.faces.len())
        .map(|f| {
            mesh.face_loops(f)
                .iter()
                .map(|l| l.len as usize)
                .sum::<usize>()
        })
        .sum()
}

/// The outward normal (in the face plane) of every face edge, in
/// face-edge order, in the mesh's coordinates; zero for degenerate edges.
pub(crate) fn face_edge_normals(mesh: &Mesh) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(face_edge_count(mesh));
    for f in 0..mesh.faces.len() {
        let n = measure::face_normal(mesh, f);
        for &l in mesh.face_loops(f) {
            let p: Vec<DVec3> = mesh.loop_points(l).collect();
            for i in 0..p.len() {
                let d = p[(i + 1) % p.len()] - p[i];
                out.push(d.cross(n).normalize_or_zero());
            }
        }
    }
    out
}

/// Index of the first face edge of every face (and the total at the end).
fn face_edge_starts(mesh: &Mesh) -> Vec<usize> {
    let mut starts = Vec::with_capacity(mesh.faces.len() + 1);
    let mut k = 0;
    for f in 0..mesh.faces.len() {
        starts.push(k);
        k += mesh
            .face_loops(f)
            .iter()
            .map(|l| l.len as usize)
            .sum::<usize>();
    }
    starts.push(k);
    starts
}

/// The face-edge index of a strip's source edge.
fn strip_edge(mesh: &Mesh, starts: &[usize], src: cga_geometry::SourceEdge) -> usize {
    let f = src.face as usize;
    let before: usize = mesh.face_loops(f)[..src.loop_index as usize]
        .iter()
        .map(|l| l.len as usize)
        .sum();
    starts[f] + before + src.edge as usize
}

/// Per-face-edge values from a float or a float array (missing: `missing`).
fn per_edge(arg: &Arg, n: usize, missing: f64) -> Result<Vec<f64>, RtError> {
    match &arg.value {
        Value::FloatArray(a) => Ok((0..n)
            .map(|k| a.data.get(k).copied().unwrap_or(missing))
            .collect()),
        _ => Ok(vec![arg.num()?; n]),
    }
}

fn warn_failed(
    cx: &mut Interp,
    span: Span,
    name: &str,
    failed: &[(usize, cga_geometry::SkeletonError)],
) {
    if let Some((f, e)) = failed.first() {
        let (f, e, n) = (*f, e.clone(), failed.len());
        cx.warn_once(span, || {
            format!(
                "{name}: face {f} could not be processed ({e}){}; it is kept whole",
                if n > 1 {
                    format!(", nor could {} other face(s)", n - 1)
                } else {
                    String::new()
                }
            )
        });
    }
}

/// Appends the faces of `src` listed in `faces` to `dst` and returns the
/// indices they got there.
fn append_faces(dst: &mut Mesh, src: &Mesh, faces: &[usize]) -> Vec<usize> {
    let first = dst.faces.len();
    let part = sub_mesh(src, faces);
    cga_geometry::transform::merge(dst, &part);
    (first..dst.faces.len()).collect()
}

// ----- offset -----

fn offset(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    let d = args[0].num()?;
    let keep = match args.get(1) {
        Some(a) => selector(a, &["all", "inside", "border"])?,
        None => "all",
    };
    // The shape an offset runs on is an occluder (context queries).
    cx.context_occluder(&st.shape);
    let mesh = st.shape.geometry.local().clone();
    if mesh.faces.is_empty() {
        return Ok(());
    }
    let o = cga_geometry::offset(&mesh, d);
    warn_failed(cx, call.span, "offset", &o.failed);
    let kinds: &[OffsetFace] = match keep {
        "inside" => &[OffsetFace::Inside],
        "border" => &[OffsetFace::Strip],
        _ => &[OffsetFace::Strip, OffsetFace::Inside],
    };
    let faces: Vec<usize> = (0..o.kinds.len())
        .filter(|&f| kinds.contains(&o.kinds[f]))
        .collect();
    let mut res = o.mesh;
    cga_geometry::uv_carry::carry_uvs(&mesh, &mut res);
    let mut out = sub_mesh(&res, &faces);
    if keep != "border" {
        // A face the skeleton failed on is kept whole, as its own inside.
        let failed: Vec<usize> = o.failed.iter().map(|(f, _)| *f).collect();
        append_faces(&mut out, &mesh, &failed);
    }
    place(&mut st.shape, out);
    Ok(())
}

// ----- setback, setbackPerEdge, setbackToArea -----

fn setback(
    cx: &mut Interp,
    st: &mut ShapeState,
    op: FootprintOp,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    let name = match op {
        FootprintOp::Setback => "setback",
        FootprintOp::SetbackPerEdge => "setbackPerEdge",
        _ => "setbackToArea",
    };
    let entries = entries(call.block.as_ref(), name, call.span)?;
    let mesh = st.shape.geometry.local().clone();
    let n = face_edge_count(&mesh);
    let mut sel = FaceEdgeSelection::new(cx, &mut st.shape);
    // The entry each face edge belongs to (the first that selects it).
    let mut owner: Vec<Option<usize>> = vec![None; n];
    for (i, e) in entries.iter().enumerate() {
        if keyword(e.head) == Some("remainder") {
            continue;
        }
        if let RExprKind::CompHead { text, .. } = &e.head.kind {
            if text.starts_with("uv.") {
                let t = text.clone();
                cx.warn_once(e.head.span, || {
                    format!("the uv selector `{t}` is not supported yet; it selects no edges")
                });
                continue;
            }
        }
        for k in sel.select(cx, frame, &st.shape, e.head)? {
            if let Some(slot) = owner.get_mut(k as usize) {
                *slot = Some(i);
            }
        }
    }
    let o = match op {
        FootprintOp::SetbackToArea => {
            let area = args[0].num()?;
            // (area [, minDistances [, maxDistances]] [, uvSet]): arrays
            // are distances, a trailing float the uv set.
            let arrays: Vec<&Arg> = args[1..]
                .iter()
                .filter(|a| matches!(a.value, Value::FloatArray(_)))
                .collect();
            let min = arrays.first().map(|a| per_edge(a, n, 0.0)).transpose()?;
            let max = arrays
                .get(1)
                .map(|a| per_edge(a, n, f64::INFINITY))
                .transpose()?;
            let selected: Vec<bool> = owner.iter().map(Option::is_some).collect();
            let (o, _, ok) = cga_geometry::setback_to_area(
                &mesh,
                area,
                &selected,
                min.as_deref(),
                max.as_deref(),
            );
            if !ok && selected.iter().any(|&s| s) {
                cx.warn_once(call.span, || {
                    format!(
                        "setbackToArea: the remainder cannot have an area of {area} with these distances; the nearest possible setback is used"
                    )
                });
            }
            o
        }
        _ => {
            let dist = per_edge(&args[0], n, 0.0)?;
            let d: Vec<f64> = (0..n)
                .map(|k| if owner[k].is_some() { dist[k] } else { 0.0 })
                .collect();
            cga_geometry::setback(&mesh, &d)
        }
    };
    warn_failed(cx, call.span, name, &o.failed);
    emit_setback(cx, st, frame, &mesh, &o, &entries, |k| owner[k])
}

/// Makes the shapes of a setback: every entry gets the strips of its edges,
/// `remainder` entries the inside faces (and faces that failed, whole).
fn emit_setback(
    cx: &mut Interp,
    st: &mut ShapeState,
    frame: &[Value],
    mesh: &Mesh,
    o: &Offset,
    entries: &[Entry],
    owner: impl Fn(usize) -> Option<usize>,
) -> Result<(), RtError> {
    let starts = face_edge_starts(mesh);
    let mut all = o.mesh.clone();
    cga_geometry::uv_carry::carry_uvs(mesh, &mut all);
    let failed: Vec<usize> = o.failed.iter().map(|(f, _)| *f).collect();
    let mut remainder = o.faces_of(OffsetFace::Inside);
    remainder.extend(append_faces(&mut all, mesh, &failed));
    st.has_successor = true;
    for (i, e) in entries.iter().enumerate() {
        let faces: Vec<usize> = if keyword(e.head) == Some("remainder") {
            remainder.clone()
        } else {
            (0..o.kinds.len())
                .filter(|&f| {
                    o.kinds[f] == OffsetFace::Strip
                        && o.source_edge[f]
                            .is_some_and(|s| owner(strip_edge(mesh, &starts, s)) == Some(i))
                })
                .collect()
        };
        spawn(cx, st, frame, &all, &faces, e.op, e.body, e.span)?;
    }
    Ok(())
}

// ----- shapeL, shapeU, shapeO -----

fn shape_luo(
    cx: &mut Interp,
    st: &mut ShapeState,
    op: FootprintOp,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    let name = match op {
        FootprintOp::ShapeL => "shapeL",
        FootprintOp::ShapeU => "shapeU",
        _ => "shapeO",
    };
    let entries = entries(call.block.as_ref(), name, call.span)?;
    for e in &entries {
        match keyword(e.head) {
            Some("shape" | "remainder") => {}
            _ => {
                return Err(RtError::new(
                    format!("`{name}` selects `shape` or `remainder`"),
                    e.head.span,
                ))
            }
        }
    }
    // Widths by scope quadrant of the edge's outward normal, as
    // setback(comp(fe) { front = .. | right = .. | back = .. | left = .. }).
    let w: Vec<f64> = args.iter().map(Arg::num).collect::<Result<_, _>>()?;
    let width = |q: Quadrant| -> f64 {
        match (op, q) {
            (_, Quadrant::Front) => w[0],
            (FootprintOp::ShapeL, Quadrant::Left) => w[1],
            (FootprintOp::ShapeU | FootprintOp::ShapeO, Quadrant::Right) => w[1],
            (FootprintOp::ShapeU, Quadrant::Left) => w[2],
            (FootprintOp::ShapeO, Quadrant::Back) => w[2],
            (FootprintOp::ShapeO, Quadrant::Left) => w[3],
            _ => 0.0,
        }
    };
    let mesh = st.shape.geometry.local().clone();
    let d: Vec<f64> = face_edge_normals(&mesh)
        .into_iter()
        .map(|n| {
            if n == DVec3::ZERO {
                0.0
            } else {
                width(quadrant_of(n))
            }
        })
        .collect();
    let o = cga_geometry::setback_luo(&mesh, &d);
    warn_failed(cx, call.span, name, &o.failed);
    let mut shape_mesh = cga_geometry::merge_strips(&o);
    cga_geometry::uv_carry::carry_uvs(&mesh, &mut shape_mesh);
    let mut with_uvs = o.mesh.clone();
    cga_geometry::uv_carry::carry_uvs(&mesh, &mut with_uvs);
    let mut rem = sub_mesh(&with_uvs, &o.faces_of(OffsetFace::Inside));
    let failed: Vec<usize> = o.failed.iter().map(|(f, _)| *f).collect();
    append_faces(&mut rem, &mesh, &failed);
    st.has_successor = true;
    for e in &entries {
        let src = if keyword(e.head) == Some("shape") {
            &shape_mesh
        } else {
            &rem
        };
        let faces: Vec<usize> = (0..src.faces.len()).collect();
        spawn(cx, st, frame, src, &faces, e.op, e.body, e.span)?;
    }
    Ok(())
}

// ----- innerRectangle, innerRect -----

/// The largest inner rectangle of face `f` and the polygons of the face
/// around it. `scope` alignment: see [`scope_rectangle`]; `edge`
/// alignment: parallel to an edge of the face (an edge longer than a
/// quarter of the longest edge of its loop).
fn face_inner_rectangle(mesh: &Mesh, f: usize, scope_aligned: bool) -> Option<(Mesh, Mesh)> {
    let shape = if scope_aligned {
        scope_rectangle(mesh, f)?
    } else {
        cga_geometry::inner_rectangle(mesh, f, None)?.0
    };
    let corners: Vec<DVec3> = shape.loop_points(shape.outer_loop(0)).collect();
    Some((shape, face_minus(mesh, f, &corners)))
}

/// Face `f` without the polygon `hole` (in its plane): the polygons left,
/// each a face (op_innerRectangle: "each polygon is put into a new shape").
fn face_minus(mesh: &Mesh, f: usize, hole: &[DVec3]) -> Mesh {
    let n = measure::face_normal(mesh, f);
    let (u, v) = cga_geometry::triangulate::plane_basis(n);
    let o = mesh.positions[mesh.corners[mesh.outer_loop(f).start as usize] as usize];
    let to2 = |p: DVec3| DVec2::new((p - o).dot(u), (p - o).dot(v));
    let face: Vec<Vec<DVec2>> = mesh
        .face_loops(f)
        .iter()
        .map(|&l| mesh.loop_points(l).map(to2).collect())
        .collect();
    let cut: Vec<DVec2> = hole.iter().map(|&p| to2(p)).collect();
    let rest = cga_geometry::footprint::difference(&face, &[cut]);
    let mut out = Mesh::new();
    out.materials = mesh.materials.clone();
    let material = mesh.faces[f].material;
    for shape in rest {
        let mut ids: Vec<Vec<u32>> = Vec::new();
        for l in &shape {
            let s = out.positions.len() as u32;
            out.positions
                .extend(l.iter().map(|q| o + u * q.x + v * q.y));
            ids.push((s..s + l.len() as u32).collect());
        }
        let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
        out.add_face(&refs, material);
    }
    out
}

/// The largest rectangle of face `f` with sides parallel to the two scope
/// axes spanning the plane the face is most parallel to, seen along the
/// third (on a slanted face a parallelogram, a rectangle seen from that
/// axis).
fn scope_rectangle(mesh: &Mesh, f: usize) -> Option<Mesh> {
    let n = measure::face_normal(mesh, f);
    if n == DVec3::ZERO {
        return None;
    }
    let a = n.abs();
    let k = if a.y >= a.x && a.y >= a.z {
        1
    } else if a.z >= a.x {
        2
    } else {
        0
    };
    // Plane axes (i, j) with i x j along +axis k, flipped when the face
    // looks the other way so that its outer loop stays counter-clockwise.
    let (i, j) = match k {
        0 => (2, 1),
        1 => (2, 0),
        _ => (0, 1),
    };
    let flip = n[k] < 0.0;
    let to2 = |p: DVec3| {
        if flip {
            DVec2::new(p[j], p[i])
        } else {
            DVec2::new(p[i], p[j])
        }
    };
    let loops: Vec<Vec<DVec2>> = mesh
        .face_loops(f)
        .iter()
        .map(|&l| mesh.loop_points(l).map(to2).collect())
        .collect();
    let axis = if flip { DVec2::Y } else { DVec2::X };
    let rect = cga_geometry::largest_inner_rectangle(&loops, axis)?;
    // Back onto the face plane along axis k.
    let p0 = mesh.positions[mesh.corners[mesh.outer_loop(f).start as usize] as usize];
    let lift = |q: DVec2| {
        let (x, y) = if flip { (q.y, q.x) } else { (q.x, q.y) };
        let mut p = DVec3::ZERO;
        p[i] = x;
        p[j] = y;
        // n . (p - p0) = 0 solved for p[k].
        p[k] = p0[k] - (n[i] * (x - p0[i]) + n[j] * (y - p0[j])) / n[k];
        p
    };
    let corners = rect.map(lift);
    let material = mesh.faces[f].material;
    let mut shape = Mesh::polygon(&corners);
    shape.materials = mesh.materials.clone();
    shape.faces[0].material = material;
    Some(shape)
}

fn inner_rectangle(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    let scope_aligned = selector(&args[0], &["scope", "edge"])? == "scope";
    let entries = entries(call.block.as_ref(), "innerRectangle", call.span)?;
    for e in &entries {
        if !matches!(keyword(e.head), Some("shape" | "remainder")) {
            return Err(RtError::new(
                "`innerRectangle` selects `shape` or `remainder`",
                e.head.span,
            ));
        }
    }
    let mesh = st.shape.geometry.local().clone();
    let mut shapes = Mesh::new();
    shapes.materials = mesh.materials.clone();
    let mut rems = Mesh::new();
    rems.materials = mesh.materials.clone();
    let mut failed = 0;
    for f in 0..mesh.faces.len() {
        match face_inner_rectangle(&mesh, f, scope_aligned) {
            Some((s, r)) => {
                cga_geometry::transform::merge(&mut shapes, &s);
                cga_geometry::transform::merge(&mut rems, &r);
            }
            None => {
                failed += 1;
                append_faces(&mut rems, &mesh, &[f]);
            }
        }
    }
    // A face that is a rectangle leaves no remainder (a face without area).
    let tiny = 1e-9 * measure::mesh_area(&mesh).max(1.0);
    let keep: Vec<usize> = (0..rems.faces.len())
        .filter(|&f| measure::face_area(&rems, f) > tiny)
        .collect();
    if keep.len() < rems.faces.len() {
        rems = sub_mesh(&rems, &keep);
    }
    cga_geometry::uv_carry::carry_uvs(&mesh, &mut shapes);
    cga_geometry::uv_carry::carry_uvs(&mesh, &mut rems);
    if failed > 0 {
        cx.warn_once(call.span, || {
            format!("innerRectangle: {failed} face(s) have no inner rectangle (no area); they are kept as remainder")
        });
    }
    st.has_successor = true;
    for e in &entries {
        let src = if keyword(e.head) == Some("shape") {
            &shapes
        } else {
            &rems
        };
        let faces: Vec<usize> = (0..src.faces.len()).collect();
        spawn(cx, st, frame, src, &faces, e.op, e.body, e.span)?;
    }
    Ok(())
}

/// `innerRect`: the geometry becomes the largest scope-aligned rectangle of
/// every face (faces without one are dropped).
fn inner_rect(st: &mut ShapeState) -> Result<(), RtError> {
    let mesh = st.shape.geometry.local().clone();
    let mut out = Mesh::new();
    out.materials = mesh.materials.clone();
    for f in 0..mesh.faces.len() {
        if let Some((s, _)) = face_inner_rectangle(&mesh, f, true) {
            cga_geometry::transform::merge(&mut out, &s);
        }
    }
    cga_geometry::uv_carry::carry_uvs(&mesh, &mut out);
    place(&mut st.shape, out);
    Ok(())
}

// ----- envelope -----

fn envelope(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    // The signatures without a direction (deprecated in 2013.0, still read)
    // erect along the face normal.
    let (direction, rest): (&str, &[Arg]) = match &args[0].value {
        Value::Str(_) => (selector(&args[0], &["normal", "world.up"])?, &args[1..]),
        _ => ("normal", args),
    };
    let Some((max_height, pairs)) = rest.split_first() else {
        return Err(RtError::new("`envelope` needs a maximum height", call.span));
    };
    let max_height = max_height.num()?;
    let mesh = st.shape.geometry.local().clone();
    if mesh.faces.is_empty() {
        return Ok(());
    }
    let n = face_edge_count(&mesh);
    let (base, angle) = match pairs {
        [b, a] if matches!(b.value, Value::FloatArray(_)) || matches!(a.value, Value::FloatArray(_)) => {
            (per_edge(b, n, 0.0)?, per_edge(a, n, 90.0)?)
        }
        rest if rest.len() % 2 == 0 && (2..=8).contains(&rest.len()) => {
            let v: Vec<f64> = rest.iter().map(Arg::num).collect::<Result<_, _>>()?;
            // (front [, back [, side | right, left]]): base height, angle.
            let pick = |q: Quadrant| -> Option<(f64, f64)> {
                let pair = |i: usize| (v[2 * i], v[2 * i + 1]);
                match (q, v.len()) {
                    (Quadrant::Front, _) => Some(pair(0)),
                    (Quadrant::Back, 4..) => Some(pair(1)),
                    (Quadrant::Left | Quadrant::Right, 6) => Some(pair(2)),
                    (Quadrant::Right, 8) => Some(pair(2)),
                    (Quadrant::Left, 8) => Some(pair(3)),
                    _ => None,
                }
            };
            // street.* selectors fall back to object.* (no street data):
            // edges are classified by their outward normal in the initial
            // shape's frame.
            let frames = Frames::for_scope(st.shape.scope.frame.axes, cx.initial.pivot.axes);
            let (mut base, mut angle) = (Vec::with_capacity(n), Vec::with_capacity(n));
            for nl in face_edge_normals(&mesh) {
                let (b, a) = if nl == DVec3::ZERO {
                    (0.0, 90.0)
                } else {
                    pick(quadrant_of(frames.object * nl)).unwrap_or((0.0, 90.0))
                };
                base.push(b);
                angle.push(a);
            }
            (base, angle)
        }
        _ => {
            return Err(RtError::new(
                "`envelope` takes (direction, maxHeight) and base height/angle pairs for the front, back, sides (or right and left), or two arrays",
                call.span,
            ))
        }
    };
    let dir = if direction == "world.up" {
        // World up in scope-local coordinates.
        Some(st.shape.scope.frame.axes.transpose() * DVec3::Y)
    } else {
        None
    };
    let e = cga_geometry::envelope::envelope(&mesh, dir, max_height, &base, &angle);
    warn_failed(cx, call.span, "envelope", &e.failed);
    let mut out = e.mesh;
    cga_geometry::tags::set_face_auto_tags(&mut out, "envelope", |f| {
        e.roles.get(f).map_or("envelope.bottom", |r| r.tag())
    });
    let failed: Vec<usize> = e.failed.iter().map(|(f, _)| *f).collect();
    append_faces(&mut out, &mesh, &failed);
    // The scope keeps its orientation and fits the volume (what CityEngine
    // gives: the Candler rule lifts its ventilators onto an envelope raised
    // from a roof face with `t(0, 0, 0.6)`, along the face's z axis).
    place(&mut st.shape, out);
    Ok(())
}

// ----- taper -----

/// `taper(height)`: a pyramid over the first face, its apex `height` above
/// the face's centroid along the face normal.
fn taper(st: &mut ShapeState, args: &[Arg]) -> Result<(), RtError> {
    let h = args[0].num()?;
    let mesh = st.shape.geometry.local().clone();
    let Some(f) = (0..mesh.faces.len()).find(|&f| measure::face_normal(&mesh, f) != DVec3::ZERO)
    else {
        return Ok(());
    };
    let n = measure::face_normal(&mesh, f);
    let outer: Vec<DVec3> = mesh.loop_points(mesh.outer_loop(f)).collect();
    // Area centroid of the outer loop (fan from its first point).
    let (mut c, mut a) = (DVec3::ZERO, 0.0);
    for i in 1..outer.len().saturating_sub(1) {
        let t = (outer[i] - outer[0]).cross(outer[i + 1] - outer[0]).dot(n) * 0.5;
        c += (outer[0] + outer[i] + outer[i + 1]) / 3.0 * t;
        a += t;
    }
    let centroid = if a.abs() > 0.0 {
        c / a
    } else {
        outer.iter().copied().sum::<DVec3>() / outer.len() as f64
    };
    let apex = centroid + n * h;
    let mut out = Mesh::new();
    out.materials = mesh.materials.clone();
    out.tags = mesh.tags.clone();
    let material = mesh.faces[f].material;
    let k = outer.len() as u32;
    out.positions.extend_from_slice(&outer);
    out.positions.push(apex);
    // The base reversed, starting at its second corner (as extrude's bottom).
    let base: Vec<u32> = (0..k).map(|i| (k + 1 - i) % k).collect();
    // Downwards the pyramid hangs below the face: base and sides turn.
    let up = h >= 0.0;
    let base_face: Vec<u32> = if up { base } else { (0..k).collect() };
    out.add_face(&[&base_face], material);
    for i in 0..k {
        let j = (i + 1) % k;
        if outer[i as usize] == outer[j as usize] {
            continue;
        }
        let side = if up { [i, j, k] } else { [j, i, k] };
        out.add_face(&[&side], material);
    }
    // The faces keep the tapered face's tags and get taper's auto-tags.
    for face in &mut out.faces {
        face.tags = mesh.faces[f].tags;
    }
    cga_geometry::tags::set_face_auto_tags(&mut out, "taper", |i| {
        if i == 0 {
            "taper.bottom"
        } else {
            "taper.side"
        }
    });
    super::roof::set_mesh_y_up(&mut st.shape, out, Some(n));
    if h < 0.0 {
        // Downwards: the scope keeps y along the normal with sy < 0 (as a
        // negative extrusion does).
        let shape = &mut st.shape;
        let sy = shape.scope.size.y;
        let y = shape.scope.frame.axes.y_axis;
        shape.scope.frame.origin += y * sy;
        shape
            .geometry
            .transform(cga_geometry::DAffine3::from_translation(DVec3::new(
                0.0, -sy, 0.0,
            )));
        shape.scope.size.y = -sy;
    }
    Ok(())
}

// ----- footprint -----

/// `footprint()`: the geometry projected orthogonally onto the scope's
/// xz-plane (y = 0), as the union of the projected faces.
fn footprint(st: &mut ShapeState) -> Result<(), RtError> {
    let mesh = st.shape.geometry.local().clone();
    let out = cga_geometry::footprint::footprint(&mesh);
    let shape = &mut st.shape;
    // The scope keeps its x and z, and lies flat at its base.
    shape.set_local_mesh(out);
    shape.scope.size.y = 0.0;
    Ok(())
}

// ----- splitAndSetbackPerimeter -----

/// `splitAndSetbackPerimeter(offset [, firstEdgeIndex, selectedEdgesMask])
/// { length : depth : operations | ... } { remainder : operations }`: the
/// chain of selected face edges (from `firstEdgeIndex`, in face-edge order,
/// wrapping around) is split like `split` splits a scope axis, starting at
/// `offset` (relative: of the chain's length) and wrapping around the
/// chain's end; every section is set back by its depth (evaluated per
/// section, with `split.index` set) and becomes a shape; the rest of the
/// faces is the remainder.
fn perimeter(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    let Some(block) = &call.block else {
        return Err(RtError::new(
            "`splitAndSetbackPerimeter` needs a `{ length : depth : operations | ... }` block",
            call.span,
        ));
    };
    if args.len() == 2 {
        return Err(RtError::new(
            "`splitAndSetbackPerimeter` takes the split offset, or the offset, the first edge index and the edge mask",
            call.span,
        ));
    }
    let mesh = st.shape.geometry.local().clone();
    let n = face_edge_count(&mesh);
    st.has_successor = true;
    let lengths: Vec<f64> = {
        let mut v = Vec::with_capacity(n);
        for f in 0..mesh.faces.len() {
            for &l in mesh.face_loops(f) {
                let p: Vec<DVec3> = mesh.loop_points(l).collect();
                for i in 0..p.len() {
                    v.push((p[(i + 1) % p.len()] - p[i]).length());
                }
            }
        }
        v
    };
    let first = match args.get(1) {
        Some(a) if n > 0 => {
            let x = a.num()?.floor();
            x.rem_euclid(n as f64) as usize % n
        }
        _ => 0,
    };
    let mask: Vec<bool> = match args.get(2) {
        Some(a) => match &a.value {
            Value::BoolArray(m) => (0..n)
                .map(|k| m.data.get(k).copied().unwrap_or(false))
                .collect(),
            Value::Bool(b) => vec![*b; n],
            other => {
                return Err(RtError::new(
                    format!(
                        "the edge mask must be a bool array, found {}",
                        crate::values::type_name(other)
                    ),
                    a.span,
                ))
            }
        },
        None => vec![true; n],
    };
    let chain: Vec<usize> = (0..n)
        .map(|i| (first + i) % n)
        .filter(|&k| mask[k])
        .collect();
    let total: f64 = chain.iter().map(|&k| lengths[k]).sum();
    let offset = args[0].size(total)?;
    let mut pattern = SplitPattern::new(block.repeat);
    let mut parts = Vec::new();
    let kind = super::split::PartsOf {
        op: "splitAndSetbackPerimeter",
        unlabeled: "a splitAndSetbackPerimeter part needs a length and a depth: `length : depth : operations`",
        part: |depth, body| (depth, body),
    };
    super::split::collect_parts(cx, frame, &st.shape, block, &mut pattern, &mut parts, &kind)?;
    let placed: Vec<Placed> = if total > 0.0 {
        crate::split_layout::layout(&pattern, total)
            .map_err(|e| RtError::new(format!("splitAndSetbackPerimeter: {e}"), call.span))?
            .into_iter()
            .filter(|p| p.size >= super::split::MIN_PART_SIZE)
            .collect()
    } else {
        Vec::new()
    };
    // The shapes first (their random streams in order), then the depths.
    let count = placed.len() as f64;
    let mut children = Vec::with_capacity(placed.len());
    let mut sections = Vec::new();
    let mut section_of = Vec::new();
    for (i, p) in placed.iter().enumerate() {
        let mut child = cx.child(&st.shape, call.span)?;
        child.split_index = p.index as f64;
        child.split_total = count;
        let depth = match parts[p.part].0 {
            Some(e) => {
                let a = cx.eval_arg(e, frame, &child)?;
                a.num()?
            }
            None => 0.0,
        };
        children.push(child);
        // Sections wrap around the chain's end.
        let start = (offset + p.start).rem_euclid(total);
        let end = start + p.size;
        if end <= total + 1e-9 {
            sections.push(perimeter::Section {
                start,
                end: end.min(total),
                depth,
            });
            section_of.push(i);
        } else {
            sections.push(perimeter::Section {
                start,
                end: total,
                depth,
            });
            section_of.push(i);
            sections.push(perimeter::Section {
                start: 0.0,
                end: end - total,
                depth,
            });
            section_of.push(i);
        }
    }
    let mut result = perimeter::split_and_setback_perimeter(&mesh, &chain, &sections);
    for m in result
        .sections
        .iter_mut()
        .chain(std::iter::once(&mut result.remainder))
    {
        cga_geometry::uv_carry::carry_uvs(&mesh, m);
    }
    let mut meshes: Vec<Mesh> = vec![Mesh::new(); placed.len()];
    for (s, m) in result.sections.iter().enumerate() {
        let i = section_of[s];
        if meshes[i].faces.is_empty() {
            meshes[i] = m.clone();
        } else {
            cga_geometry::transform::merge(&mut meshes[i], m);
        }
    }
    for ((p, mut child), m) in placed.iter().zip(children).zip(meshes) {
        if m.faces.is_empty() {
            continue;
        }
        place(&mut child, m);
        let mut cst = ShapeState::new(child);
        cx.exec_body(parts[p.part].1, frame, &mut cst)?;
        cx.finish(cst);
    }
    if let Some(rb) = &call.remainder_block {
        let entries = entries(Some(rb), "splitAndSetbackPerimeter", call.span)?;
        for e in &entries {
            if keyword(e.head) != Some("remainder") {
                return Err(RtError::new(
                    "the second block of `splitAndSetbackPerimeter` is `{ remainder : operations }`",
                    e.head.span,
                ));
            }
            let faces: Vec<usize> = (0..result.remainder.faces.len()).collect();
            spawn(
                cx,
                st,
                frame,
                &result.remainder,
                &faces,
                BlockOp::Equals,
                e.body,
                e.span,
            )?;
        }
    }
    Ok(())
}
