//! Texturing: `setupProjection`, `projectUV`, `translateUV`, `scaleUV`,
//! `rotateUV`, `normalizeUV`, `tileUV`, `deleteUV`, `copyUV`, `texture`,
//! `insertAlongUV` (in [`insert_along_uv`]);
//! the cut along iso-lines of a texture coordinate behind `split(u|v, ...)`;
//! and how texture paths written in rules become files.
//!
//! # Texture coordinates
//!
//! A mesh carries up to ten UV sets, one per texture layer
//! (`cga_geometry::TEXTURE_CHANNELS`: set 0 for the colour map, 2 for the
//! dirt map, ...), per face corner. `setupProjection` only records a
//! [`Projection`] on the shape, in object coordinates; the shapes derived
//! from it inherit it, and `projectUV` evaluates it at the vertices of the
//! geometry the shape has by then. So a facade that sets up its projection
//! and is then split into tiles that each call `projectUV` gets coordinates
//! that run on continuously across the tiles.
//!
//! The projection (as CityEngine computes it, checked against its output):
//! a point with coordinates `(a, b, c)` along the chosen u, v and w = u × v
//! axes gets `u = (a - widthOffset - uwFactor * c) / textureWidth` and
//! `v = (b - heightOffset) / textureHeight`. The five-argument form
//! `setupProjection(set, axes, w, h, uwFactor)` is the older spelling with
//! the uw factor (Candler uses it). Sizes and offsets may be relative (`'2`:
//! twice the scope's extent along that axis); a floating size (`~2`) is
//! adjusted so that a whole number of tiles spans the extent.
//!
//! # Texture paths
//!
//! A rule writes a texture path relative to its rule file (or its project's
//! `assets/` folder, or workspace-absolute). The material keeps the path as
//! written, so `material.colormap` reads back what was set. When a leaf's
//! geometry is emitted, every texture path is resolved from the rule file
//! of the rule that emits the shape ([`TextureFiles::resolve_mesh`]) and
//! replaced by the absolute path of the file found; paths that name no file
//! stay as written (the exporter looks for them once more and warns).
//! `builtin:` textures are left to the exporter, which generates them.

pub mod insert_along_uv;

use std::sync::Arc;

use cga_geometry::measure::{uv_bounds, uv_unit_scale};
use cga_geometry::topology::FxHashMap;
use cga_geometry::{DMat3, DVec2, DVec3, Face, Loop, Mesh, UV_SETS};
use cga_syntax::FileId;
use cga_value::Value;

use super::transform::selector;
use super::TextureOp;
use crate::assets::Assets;
use crate::derive::{Arg, Interp, MaterialEdit, RtError, ShapeState, SizeKind};
use crate::expr::OpCall;
use crate::material_attr::MatField;
use crate::shape::{Frame, Projection, Shape};

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    op: TextureOp,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    let shape = &mut st.shape;
    // Sets nobody keeps or reads are not computed (`crate::uv_use`): the
    // operations that only write their coordinates stop once their
    // arguments are read.
    let uv_skip = cx.uv_skip;
    let skipped = |set: usize| uv_skip & (1 << set) != 0;
    match op {
        TextureOp::SetupProjection => setup_projection(cx, shape, call, args),
        TextureOp::ProjectUV => {
            let set = uv_set(&args[0])?;
            match shape.projections.as_ref().and_then(|p| p[set]) {
                Some(_) if skipped(set) => {}
                Some(p) => project_uv(shape, set, &p),
                None => cx.warn_once(call.span, || {
                    format!("projectUV({set}): no projection was set up for uv set {set} (setupProjection); the shape is left unchanged")
                }),
            }
            Ok(())
        }
        TextureOp::TranslateUV => {
            let set = uv_set(&args[0])?;
            let d = DVec2::new(args[1].num()?, args[2].num()?);
            if skipped(set) {
                return Ok(());
            }
            edit_uvs(shape, set, |_, uvs| uvs.iter_mut().for_each(|t| *t += d));
            Ok(())
        }
        TextureOp::ScaleUV => {
            let set = uv_set(&args[0])?;
            let f = DVec2::new(args[1].num()?, args[2].num()?);
            if skipped(set) {
                return Ok(());
            }
            edit_uvs(shape, set, |_, uvs| uvs.iter_mut().for_each(|t| *t *= f));
            Ok(())
        }
        TextureOp::RotateUV => {
            let set = uv_set(&args[0])?;
            // Counter-clockwise about (0, 0), in degrees.
            let (s, c) = args[1].num()?.to_radians().sin_cos();
            if skipped(set) {
                return Ok(());
            }
            edit_uvs(shape, set, |_, uvs| {
                for t in uvs.iter_mut() {
                    *t = DVec2::new(c * t.x - s * t.y, s * t.x + c * t.y);
                }
            });
            Ok(())
        }
        TextureOp::NormalizeUV => {
            let set = uv_set(&args[0])?;
            let mode = selector(&args[1], &["uv", "uvUniform", "u", "v"])?;
            let per_face = selector(&args[2], &["separatePerFace", "collectiveAllFaces"])?
                == "separatePerFace";
            let mode = match mode {
                "uv" => Normalize::Both,
                "uvUniform" => Normalize::Uniform,
                "u" => Normalize::U,
                _ => Normalize::V,
            };
            if skipped(set) {
                return Ok(());
            }
            edit_uvs(shape, set, |mesh, uvs| {
                normalize_uvs(mesh, uvs, mode, per_face)
            });
            Ok(())
        }
        TextureOp::TileUV if skipped(uv_set(&args[0])?) => Ok(()),
        TextureOp::TileUV => tile_uv(cx, shape, call, args),
        TextureOp::DeleteUV => {
            let set = uv_set(&args[0])?;
            if !skipped(set) && shape.geometry.raw().0.uvs[set].is_some() {
                shape.geometry.local_mut().uvs[set] = None;
            }
            Ok(())
        }
        TextureOp::CopyUV => {
            let from = uv_set(&args[0])?;
            let to = uv_set(&args[1])?;
            let mesh = shape.geometry.raw().0;
            if !skipped(to) && from != to && mesh.uvs[from] != mesh.uvs[to] {
                let m = shape.geometry.local_mut();
                m.uvs[to] = m.uvs[from].clone();
            }
            Ok(())
        }
        TextureOp::Texture => texture(cx, shape, call, &args[0]),
        TextureOp::InsertAlongUV => insert_along(cx, shape, call, args),
    }
}

/// `insertAlongUV(set, path, height[, scope.y|vertex.normal[, alignPosition|keepPosition]])`.
fn insert_along(
    cx: &mut Interp,
    shape: &mut Shape,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    let set = uv_set(&args[0])?;
    let path = args[1].text()?;
    let height = args[2].num()?;
    let along_normals = match args.get(3) {
        Some(a) => selector(a, &["scope.y", "vertex.normal"])? == "vertex.normal",
        None => false,
    };
    let keep_position = match args.get(4) {
        Some(a) => selector(a, &["alignPosition", "keepPosition"])? == "keepPosition",
        None => false,
    };
    let asset = match cx.memo.asset(cx.assets, call.span.file, path) {
        Ok(a) => a,
        Err(message) => {
            // As with `i`: a missing asset must not lose the model.
            cx.warn_once(args[1].span, || {
                format!("{message}; the shape keeps its geometry")
            });
            return Ok(());
        }
    };
    let surface = shape.geometry.local().clone();
    if surface.uvs[set].is_none() {
        cx.warn_once(call.span, || {
            format!("insertAlongUV: the shape has no texture coordinates in uv set {set}; the asset is not inserted")
        });
        return Ok(());
    }
    let place = insert_along_uv::Placement {
        height,
        along_normals,
        keep_position,
    };
    // Scope-local coordinates: the scope's y axis is (0, 1, 0).
    match insert_along_uv::insert_along_uv(&surface, set, &asset, place, DVec3::Y) {
        Some(mesh) => shape.set_local_mesh(mesh),
        None => cx.warn_once(call.span, || {
            format!(
                "insertAlongUV: the uv range needs more than {} copies of the asset; the shape keeps its geometry",
                insert_along_uv::MAX_TILES
            )
        }),
    }
    Ok(())
}

/// A UV set argument: an integer in [0, 9].
pub fn uv_set(arg: &Arg) -> Result<usize, RtError> {
    let k = arg.num()?;
    if (0.0..UV_SETS as f64).contains(&k) && k.fract() == 0.0 {
        Ok(k as usize)
    } else {
        Err(RtError::new(
            format!("uv set {k} is not an integer in [0, 9]"),
            arg.span,
        ))
    }
}

/// The axes selectors of `setupProjection`.
const PROJECTION_AXES: [&str; 12] = [
    "scope.xy", "scope.xz", "scope.yx", "scope.yz", "scope.zx", "scope.zy", "world.xy", "world.xz",
    "world.yx", "world.yz", "world.zx", "world.zy",
];

fn setup_projection(
    cx: &mut Interp,
    shape: &mut Shape,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    let set = uv_set(&args[0])?;
    let axes = selector(&args[1], &PROJECTION_AXES)?;
    let (system, pair) = axes.split_at(axes.len() - 2);
    let index = |c: u8| (c - b'x') as usize;
    let (iu, iv) = (index(pair.as_bytes()[0]), index(pair.as_bytes()[1]));
    let (origin, basis) = if system == "scope." {
        (shape.scope.frame.origin, shape.scope.frame.axes)
    } else {
        (DVec3::ZERO, DMat3::IDENTITY)
    };
    let (au, av) = (basis.col(iu), basis.col(iv));
    let frame = Frame {
        origin,
        axes: DMat3::from_cols(au, av, au.cross(av)),
    };
    // The extent the relative and floating forms refer to: the scope's size
    // along the axis, or for world axes the geometry's.
    let extent = if system == "scope." {
        DVec2::new(shape.scope.size[iu], shape.scope.size[iv])
    } else {
        let mesh = shape.object_mesh();
        let span = |a: DVec3| {
            let mut it = mesh
                .corners
                .iter()
                .map(|&c| mesh.positions[c as usize].dot(a));
            let first = it.next().unwrap_or(0.0);
            let (lo, hi) = it.fold((first, first), |(lo, hi), x| (lo.min(x), hi.max(x)));
            hi - lo
        };
        DVec2::new(span(au), span(av))
    };
    let size = DVec2::new(
        tile_size(&args[2], extent.x)?,
        tile_size(&args[3], extent.y)?,
    );
    if size.x == 0.0 || size.y == 0.0 || !size.is_finite() {
        cx.warn_once(call.span, || {
            format!("setupProjection: the texture size must not be 0 (found {} x {}); no projection is set up", size.x, size.y)
        });
        return Ok(());
    }
    let (offset, uw) = match args.len() {
        5 => (DVec2::ZERO, args[4].num()?),
        6 | 7 => (
            DVec2::new(args[4].size(extent.x)?, args[5].size(extent.y)?),
            match args.get(6) {
                Some(a) => a.num()?,
                None => 0.0,
            },
        ),
        _ => (DVec2::ZERO, 0.0),
    };
    let projections = Arc::make_mut(shape.projections.get_or_insert_with(Default::default));
    projections[set] = Some(Projection {
        frame,
        size,
        offset,
        uw,
    });
    Ok(())
}

/// A texture tile size: absolute; relative to `extent` (`'0.5`: two tiles
/// span it); or floating (`~2`: the nearest size that spans `extent` with a
/// whole number of tiles).
fn tile_size(arg: &Arg, extent: f64) -> Result<f64, RtError> {
    let x = arg.num()?;
    Ok(match arg.kind {
        SizeKind::Absolute => x,
        SizeKind::Relative => x * extent,
        SizeKind::Floating => floating_tile(x, extent),
    })
}

/// The size nearest to `x` that spans `extent` a whole number of times (at
/// least once), with the sign of `x`.
fn floating_tile(x: f64, extent: f64) -> f64 {
    let extent = extent.abs();
    if x == 0.0 || extent == 0.0 || !extent.is_finite() {
        return x;
    }
    let n = (extent / x.abs()).round().max(1.0);
    x.signum() * extent / n
}

/// Bakes projection `p` into UV set `set` of the shape's geometry.
pub fn project_uv(shape: &mut Shape, set: usize, p: &Projection) {
    if shape.geometry.is_empty() {
        return;
    }
    let frame = shape.scope.frame;
    // In place: the geometry is usually this shape's own (a piece just cut),
    // and the UV array of a set being re-projected is reused.
    let m = shape.geometry.local_mut();
    PROJECTED.with(|at| {
        let mut at = at.borrow_mut();
        at.clear();
        at.extend(m.positions.iter().map(|&q| p.uv(frame.to_object(q))));
        let mut uvs = m.uvs[set].take().unwrap_or_default();
        uvs.clear();
        uvs.extend(m.corners.iter().map(|&c| at[c as usize]));
        m.uvs[set] = Some(uvs);
        // The room of one huge mesh is not kept for the thread's lifetime.
        if at.capacity() > KEPT_PROJECTED {
            *at = Vec::new();
        }
    });
}

/// Positions' room kept between projections (a building's largest meshes).
const KEPT_PROJECTED: usize = 1 << 16;

thread_local! {
    /// The texture coordinates of each position, reused by `project_uv`.
    static PROJECTED: std::cell::RefCell<Vec<DVec2>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Runs `f` on UV set `set` of the shape's geometry (scope-local), if the
/// geometry has that set; a geometry without it is left alone.
fn edit_uvs(shape: &mut Shape, set: usize, f: impl FnOnce(&Mesh, &mut Vec<DVec2>)) {
    if shape.geometry.raw().0.uvs[set].is_none() {
        return;
    }
    let m = shape.geometry.local_mut();
    if let Some(mut uvs) = m.uvs[set].take() {
        f(m, &mut uvs);
        m.uvs[set] = Some(uvs);
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Normalize {
    Both,
    Uniform,
    U,
    V,
}

/// `normalizeUV`: moves the smallest coordinates to 0 and scales the range
/// to 1, over all corners or face by face. `uvUniform` scales both
/// directions by the larger range, keeping the texture's aspect.
fn normalize_uvs(mesh: &Mesh, uvs: &mut [DVec2], mode: Normalize, per_face: bool) {
    let apply = |uvs: &mut [DVec2], corners: &mut dyn Iterator<Item = usize>| {
        let idx: Vec<usize> = corners.collect();
        let Some(&first) = idx.first() else { return };
        let (lo, hi) = idx.iter().fold((uvs[first], uvs[first]), |(lo, hi), &c| {
            (lo.min(uvs[c]), hi.max(uvs[c]))
        });
        let range = hi - lo;
        let inv = |r: f64| if r.abs() > 1e-300 { 1.0 / r } else { 0.0 };
        let scale = match mode {
            Normalize::Uniform => DVec2::splat(inv(range.x.max(range.y))),
            _ => DVec2::new(inv(range.x), inv(range.y)),
        };
        for &c in &idx {
            let n = (uvs[c] - lo) * scale;
            match mode {
                Normalize::U => uvs[c].x = n.x,
                Normalize::V => uvs[c].y = n.y,
                _ => uvs[c] = n,
            }
        }
    };
    if per_face {
        for f in 0..mesh.faces.len() {
            let mut it = mesh
                .face_loops(f)
                .iter()
                .flat_map(|&l| mesh.loop_corners(l));
            apply(uvs, &mut it);
        }
    } else {
        // Corners of faces only: stray attribute entries do not count.
        let mut it = (0..mesh.faces.len()).flat_map(|f| {
            mesh.face_loops(f)
                .iter()
                .flat_map(|&l| mesh.loop_corners(l))
                .collect::<Vec<_>>()
        });
        apply(uvs, &mut it);
    }
}

/// `tileUV(set, width, height)`: rescales the set so that one texture tile
/// covers `width` x `height` scene units of the surface, starting at the
/// smallest coordinates. Relative sizes are fractions of the set's extent
/// on the surface (`'0.5`: two tiles), floating sizes are adjusted to fit a
/// whole number of tiles, and 0 leaves that direction alone.
fn tile_uv(cx: &mut Interp, shape: &mut Shape, call: &OpCall, args: &[Arg]) -> Result<(), RtError> {
    let set = uv_set(&args[0])?;
    if shape.geometry.raw().0.uvs[set].is_none() {
        return Ok(());
    }
    // An inserted asset placed like one before (the windows of a facade)
    // has the same measures: they are remembered.
    let (raw, to_scope) = shape.geometry.raw();
    let shared = Arc::strong_count(raw) > 1;
    let known = if shared {
        cx.memo.uv(raw, to_scope, set)
    } else {
        None
    };
    let (bounds, unit) = match known {
        Some(m) => m,
        None => {
            let key = shared.then(|| (raw.clone(), to_scope.copied()));
            // Borrowed, not shared: `edit_uvs` below then edits an unshared
            // mesh in place.
            let mesh = shape.geometry.local();
            // Scene units per unit of u and of v (None: no usable
            // parameterisation).
            let m = (uv_bounds(mesh, set), uv_unit_scale(mesh, set));
            if let Some((raw, to_scope)) = key {
                cx.memo.remember_uv(raw, to_scope, set, m);
            }
            m
        }
    };
    let Some((lo, hi)) = bounds else {
        return Ok(());
    };
    let range = hi - lo;
    let mut factor = DVec2::ONE;
    for (k, arg) in args[1..3].iter().enumerate() {
        let x = arg.num()?;
        let r = range[k];
        factor[k] = match arg.kind {
            _ if x == 0.0 => 1.0,
            _ if r.abs() <= 1e-300 => 1.0,
            SizeKind::Relative => 1.0 / (x * r),
            SizeKind::Absolute | SizeKind::Floating => match unit.map(|u| u[k]) {
                Some(s) if s > 0.0 => {
                    let extent = r * s;
                    let tile = if arg.kind == SizeKind::Floating {
                        floating_tile(x, extent)
                    } else {
                        x
                    };
                    s / tile
                }
                _ => {
                    cx.warn_once(call.span, || {
                        "tileUV: the texture coordinates do not span the surface; left unchanged"
                            .to_string()
                    });
                    return Ok(());
                }
            },
        };
    }
    let keep = DVec2::new(
        if args[1].num()? == 0.0 { 1.0 } else { 0.0 },
        if args[2].num()? == 0.0 { 1.0 } else { 0.0 },
    );
    edit_uvs(shape, set, |_, uvs| {
        for t in uvs.iter_mut() {
            // A direction left alone keeps its coordinates as they are.
            let moved = (*t - lo) * factor;
            *t = moved + keep * (*t - moved);
        }
    });
    Ok(())
}

/// `texture(path)`: sets the colour map and, as CityEngine does, the
/// opacity map to the same file if the image has an alpha channel (else to
/// "").
fn texture(cx: &mut Interp, shape: &mut Shape, call: &OpCall, arg: &Arg) -> Result<(), RtError> {
    let path: Arc<str> = match &arg.value {
        Value::Str(s) => s.clone(),
        other => Arc::from(crate::values::to_text(other).as_str()),
    };
    let edit = MaterialEdit::Texture(path.clone(), call.span.file);
    cx.edit_material(shape, edit, |cx, m| {
        let alpha = cx.textures.has_alpha(cx.assets, call.span.file, &path);
        let opacity = if alpha { path.clone() } else { empty_str() };
        for (field, v) in [(MatField::Map(0), path), (MatField::Map(4), opacity)] {
            m.set(field, &Value::Str(v))
                .map_err(|e| RtError::new(e, arg.span))?;
        }
        Ok(())
    })
}

/// A shared empty string (`Arc::from("")` would allocate every time).
fn empty_str() -> Arc<str> {
    static EMPTY: std::sync::LazyLock<Arc<str>> = std::sync::LazyLock::new(|| Arc::from(""));
    EMPTY.clone()
}

/// Texture files named by rules: where they are and whether they have an
/// alpha channel, found once per path and rule file (per initial shape).
#[derive(Default)]
pub struct TextureFiles {
    found: FxHashMap<(u32, Arc<str>), Option<Arc<str>>>,
    alpha: FxHashMap<Arc<str>, bool>,
}

impl TextureFiles {
    /// The absolute path of the texture `path` as written in rule file
    /// `from`, if such a file exists. `builtin:` names are not files.
    pub fn resolve(&mut self, assets: &Assets, from: FileId, path: &Arc<str>) -> Option<Arc<str>> {
        if path.is_empty() || path.starts_with("builtin:") {
            return None;
        }
        if let Some(r) = self.found.get(&(from.0, path.clone())) {
            return r.clone();
        }
        let r = assets.texture_file(from, path);
        self.found.insert((from.0, path.clone()), r.clone());
        r
    }

    /// Whether the texture `path` (written in rule file `from`) has an alpha
    /// channel: PNG with an alpha channel or transparency, 32-bit TGA.
    /// Missing and unreadable files have none.
    pub fn has_alpha(&mut self, assets: &Assets, from: FileId, path: &Arc<str>) -> bool {
        let Some(file) = self.resolve(assets, from, path) else {
            return false;
        };
        if let Some(&a) = self.alpha.get(&file) {
            return a;
        }
        let a = assets.texture_alpha(&file, |head| image_has_alpha(&file, head));
        self.alpha.insert(file, a);
        a
    }

    /// Replaces the texture paths of `mesh`'s materials by the files they
    /// name, searched from rule file `from` (see the module docs).
    pub fn resolve_mesh(&mut self, assets: &Assets, from: FileId, mesh: &mut Mesh) {
        self.resolve_materials(assets, from, &mut mesh.materials);
    }

    /// [`resolve_mesh`](TextureFiles::resolve_mesh) for a list of materials;
    /// a shared list is copied only if a path changes.
    pub fn resolve_materials(
        &mut self,
        assets: &Assets,
        from: FileId,
        materials: &mut cga_geometry::mesh::SharedVec<cga_geometry::Material>,
    ) {
        for i in 0..materials.len() {
            for k in 0..materials[i].maps.len() {
                let path = &materials[i].maps[k].path;
                if let Some(found) = self.resolve(assets, from, path) {
                    if found != *path {
                        materials.make_mut()[i].maps[k].path = found;
                    }
                }
            }
        }
    }
}

/// Whether an image file, of which `head` holds the first bytes, has an
/// alpha channel.
fn image_has_alpha(path: &str, head: &[u8]) -> bool {
    if head.starts_with(b"\x89PNG\r\n\x1a\n") {
        return png_has_alpha(head);
    }
    let ext = std::path::Path::new(path)
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if ext.as_deref() == Some("tga") && head.len() >= 18 {
        // TGA: byte 16 is the pixel depth.
        return head[16] == 32;
    }
    false
}

/// PNG: colour type 4 or 6 (grey or RGB with alpha), or a `tRNS` chunk
/// before the image data.
fn png_has_alpha(bytes: &[u8]) -> bool {
    if bytes.len() < 26 {
        return false;
    }
    if matches!(bytes[25], 4 | 6) {
        return true;
    }
    let mut pos = 8;
    while pos + 8 <= bytes.len() {
        let len = u32::from_be_bytes([bytes[pos], bytes[pos + 1], bytes[pos + 2], bytes[pos + 3]])
            as usize;
        match &bytes[pos + 4..pos + 8] {
            b"tRNS" => return true,
            b"IDAT" | b"IEND" => return false,
            _ => {}
        }
        pos = pos.saturating_add(12).saturating_add(len);
    }
    false
}

// ---------------------------------------------------------------------------
// Cutting along iso-lines of a texture coordinate (the uv split).
// ---------------------------------------------------------------------------

/// Cuts `mesh` along the lines where coordinate `axis` (0: u, 1: v) of UV
/// set `set` takes the values `cuts` (ascending), into `cuts.len() + 1`
/// slabs: slab `i` holds the surface between `cuts[i - 1]` and `cuts[i]`.
/// Every slab keeps the material slots, groups and attribute sets of
/// `mesh`. A mesh without that set goes whole into slab 0.
///
/// Texture coordinates are a parameterisation of the surface, so the cut
/// is made face by face, and how depends on the face:
///
/// - If the coordinate is an affine function on the (planar) face, as
///   projections and most assets give, the line where it equals `c` is the
///   face's intersection with a plane: the face is cut in 3D with the
///   parallel planes `g · p = c'` (`g` the coordinate's gradient), exactly.
/// - Otherwise (a street quad whose two sides have different lengths but
///   both run from u = 0 to 1) the face is cut in its texture space: its
///   corners are placed at their (u, v), its 3D positions ride along as two
///   spare UV sets, and since the cut interpolates every attribute along
///   the edges it crosses, the cut corners land where the texture
///   coordinate takes the cut value on each edge, joined by straight lines.
/// - A face whose texture-space polygon has no area, or with all ten sets
///   in use (no spare set), falls back to the plane of the best affine fit.
///
/// Faces that no cut crosses are copied whole, so the work is linear in the
/// faces plus the pieces. Cut faces do not share the vertices of their
/// cuts with their neighbours (positions agree to rounding); closed meshes
/// are not capped: this cuts a surface along its parameterisation.
pub fn cut_along_uv(mesh: &Mesh, set: usize, axis: usize, cuts: &[f64]) -> Vec<Mesh> {
    let mut slabs: Vec<Mesh> = (0..=cuts.len()).map(|_| empty_like(mesh)).collect();
    let Some(uvs) = mesh.uvs.get(set).and_then(|u| u.as_deref()) else {
        if let Some(first) = slabs.first_mut() {
            *first = mesh.clone();
        }
        return slabs;
    };
    let mut remaps: Vec<Vec<u32>> = vec![Vec::new(); slabs.len()];
    let mut scratch = Mesh::new();
    for f in 0..mesh.faces.len() {
        let corners = || {
            mesh.face_loops(f)
                .iter()
                .flat_map(|&l| mesh.loop_corners(l))
        };
        let (lo, hi) = corners().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
            let x = uvs.get(c).map_or(0.0, |t| t[axis]);
            (lo.min(x), hi.max(x))
        });
        let eps = 1e-9 * (1.0 + lo.abs().max(hi.abs()));
        let mut first = cuts.partition_point(|&c| c <= lo + eps);
        let mut last = cuts.partition_point(|&c| c < hi - eps).max(first);
        if first == cuts.len() && first > 0 && hi <= cuts[first - 1] + eps {
            // A face on the last cut (the far end of the range, an end
            // wall) belongs to the slab below it, not to the empty one above.
            first -= 1;
            last = first;
        }
        if first == last || mesh.outer_loop(f).len < 3 {
            copy_face(mesh, f, &mut slabs[first], &mut remaps[first]);
            continue;
        }
        let face = mesh.faces[f];
        let pieces = cut_face(mesh, f, set, axis, &cuts[first..last], &mut scratch);
        match pieces {
            Some(pieces) => {
                for (j, piece) in pieces.iter().enumerate() {
                    append_piece(&mut slabs[first + j], piece, face);
                }
            }
            None => {
                // No way to cut (no gradient): the face goes where its middle is.
                let mid = 0.5 * (lo + hi);
                let k = cuts.partition_point(|&c| c <= mid);
                copy_face(mesh, f, &mut slabs[k], &mut remaps[k]);
            }
        }
    }
    slabs
}

/// An empty mesh with `mesh`'s material slots, groups and attribute sets.
fn empty_like(mesh: &Mesh) -> Mesh {
    let mut m = Mesh::new();
    m.materials = mesh.materials.clone();
    m.groups = mesh.groups.clone();
    m.tags = mesh.tags.clone();
    for (dst, src) in m.uvs.iter_mut().zip(&mesh.uvs) {
        if src.is_some() {
            *dst = Some(Vec::new());
        }
    }
    if mesh.normals.is_some() {
        m.normals = Some(Vec::new());
    }
    m
}

/// Copies face `f` of `mesh` into `out`; `remap` (position of `mesh` →
/// position of `out`) keeps vertices shared between copied faces.
fn copy_face(mesh: &Mesh, f: usize, out: &mut Mesh, remap: &mut Vec<u32>) {
    if remap.is_empty() {
        remap.resize(mesh.positions.len(), u32::MAX);
    }
    let face = mesh.faces[f];
    let first_loop = out.loops.len() as u32;
    for &l in mesh.face_loops(f) {
        let start = out.corners.len() as u32;
        for c in mesh.loop_corners(l) {
            let p = mesh.corners[c] as usize;
            if remap[p] == u32::MAX {
                remap[p] = out.positions.len() as u32;
                out.positions.push(mesh.positions[p]);
            }
            out.corners.push(remap[p]);
            for (dst, src) in out.uvs.iter_mut().zip(&mesh.uvs) {
                if let (Some(d), Some(s)) = (dst.as_mut(), src.as_ref()) {
                    d.push(s.get(c).copied().unwrap_or(DVec2::ZERO));
                }
            }
            if let (Some(d), Some(s)) = (out.normals.as_mut(), mesh.normals.as_ref()) {
                d.push(s.get(c).copied().unwrap_or(DVec3::ZERO));
            }
        }
        out.loops.push(Loop { start, len: l.len });
    }
    out.faces.push(Face { first_loop, ..face });
}

/// Appends all faces of `piece` (a cut of one face) to `out` with the
/// original face's material and group.
fn append_piece(out: &mut Mesh, piece: &Mesh, face: Face) {
    let base = out.positions.len() as u32;
    out.positions.extend_from_slice(&piece.positions);
    let corner_base = out.corners.len() as u32;
    let loop_base = out.loops.len() as u32;
    out.corners.extend(piece.corners.iter().map(|&c| c + base));
    out.loops.extend(piece.loops.iter().map(|l| Loop {
        start: l.start + corner_base,
        len: l.len,
    }));
    out.faces.extend(piece.faces.iter().map(|pf| Face {
        first_loop: pf.first_loop + loop_base,
        loop_count: pf.loop_count,
        material: face.material,
        group: face.group,
        tags: face.tags,
    }));
    let n = piece.corners.len();
    for (dst, src) in out.uvs.iter_mut().zip(&piece.uvs) {
        if let Some(d) = dst.as_mut() {
            match src {
                Some(s) => d.extend_from_slice(s),
                None => d.resize(d.len() + n, DVec2::ZERO),
            }
        }
    }
    if let Some(d) = out.normals.as_mut() {
        match &piece.normals {
            Some(s) => d.extend_from_slice(s),
            None => d.resize(d.len() + n, DVec3::ZERO),
        }
    }
}

/// Cuts face `f` at the values `cuts` of coordinate `axis` of set `set`
/// into `cuts.len() + 1` pieces (each a mesh of zero or more faces), or
/// `None` if the coordinate does not vary on the face.
fn cut_face(
    mesh: &Mesh,
    f: usize,
    set: usize,
    axis: usize,
    cuts: &[f64],
    scratch: &mut Mesh,
) -> Option<Vec<Mesh>> {
    let uvs = mesh.uvs[set].as_deref()?;
    // The face alone, one position per corner (the cut welds them).
    scratch.positions.clear();
    scratch.corners.clear();
    scratch.loops.clear();
    scratch.faces.clear();
    for (dst, src) in scratch.uvs.iter_mut().zip(&mesh.uvs) {
        *dst = src.as_ref().map(|_| Vec::new());
    }
    scratch.normals = mesh.normals.as_ref().map(|_| Vec::new());
    let mut src_corners: Vec<usize> = Vec::new();
    for &l in mesh.face_loops(f) {
        let start = scratch.corners.len() as u32;
        for c in mesh.loop_corners(l) {
            scratch.corners.push(scratch.positions.len() as u32);
            scratch
                .positions
                .push(mesh.positions[mesh.corners[c] as usize]);
            src_corners.push(c);
        }
        scratch.loops.push(Loop { start, len: l.len });
    }
    for (dst, src) in scratch.uvs.iter_mut().zip(&mesh.uvs) {
        if let (Some(d), Some(s)) = (dst.as_mut(), src.as_ref()) {
            d.extend(
                src_corners
                    .iter()
                    .map(|&c| s.get(c).copied().unwrap_or(DVec2::ZERO)),
            );
        }
    }
    if let (Some(d), Some(s)) = (scratch.normals.as_mut(), mesh.normals.as_ref()) {
        d.extend(
            src_corners
                .iter()
                .map(|&c| s.get(c).copied().unwrap_or(DVec3::ZERO)),
        );
    }
    scratch.faces.push(Face {
        first_loop: 0,
        loop_count: scratch.loops.len() as u32,
        material: 0,
        group: 0,
        tags: 0,
    });
    let values: Vec<f64> = src_corners
        .iter()
        .map(|&c| uvs.get(c).map_or(0.0, |t| t[axis]))
        .collect();

    let fit = affine_fit(&scratch.positions, &values);
    if let Some(fit) = &fit {
        if fit.exact {
            return Some(cut_by_gradient(scratch, fit, cuts));
        }
    }
    if let Some(pieces) = cut_in_texture_space(scratch, set, axis, cuts) {
        return Some(pieces);
    }
    fit.map(|fit| cut_by_gradient(scratch, &fit, cuts))
}

/// An affine function `value(p) = value0 + g · (p - p0)` over a face's plane.
struct AffineFit {
    p0: DVec3,
    value0: f64,
    g: DVec3,
    /// Whether it reproduces every corner's value and the face is planar.
    exact: bool,
}

/// The affine function through three well-spread corners of a face, and
/// whether it fits all corners. `None` if the face has no area or the
/// coordinate does not vary along it.
fn affine_fit(points: &[DVec3], values: &[f64]) -> Option<AffineFit> {
    let p0 = *points.first()?;
    let far = |from: &dyn Fn(DVec3) -> f64| {
        (0..points.len()).max_by(|&a, &b| from(points[a]).total_cmp(&from(points[b])))
    };
    let i1 = far(&|p| (p - p0).length_squared())?;
    let e1 = points[i1] - p0;
    let i2 = far(&|p| e1.cross(p - p0).length_squared())?;
    let e2 = points[i2] - p0;
    let n = e1.cross(e2);
    let nn = n.length_squared();
    let size = e1.length();
    let spread = nn.is_finite() && nn > 1e-24 * size.powi(4);
    if !spread {
        return None;
    }
    let (d1, d2) = (values[i1] - values[0], values[i2] - values[0]);
    let g = (e2.cross(n) * d1 + n.cross(e1) * d2) / nn;
    let varies = g.is_finite() && g.length_squared() > 0.0;
    if !varies {
        return None;
    }
    let (lo, hi) = values.iter().fold((values[0], values[0]), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    let tol_value = 1e-6 * (hi - lo).max(1e-12);
    let unit_n = n / nn.sqrt();
    let tol_plane = 1e-7 * size.max(1e-9);
    let exact = points.iter().zip(values).all(|(&p, &v)| {
        let d = p - p0;
        (values[0] + g.dot(d) - v).abs() <= tol_value && unit_n.dot(d).abs() <= tol_plane
    });
    Some(AffineFit {
        p0,
        value0: values[0],
        g,
        exact,
    })
}

/// Cuts `face` with the planes where the fitted coordinate takes each cut
/// value.
fn cut_by_gradient(face: &Mesh, fit: &AffineFit, cuts: &[f64]) -> Vec<Mesh> {
    let len = fit.g.length();
    let normal = fit.g / len;
    let offsets: Vec<f64> = cuts
        .iter()
        .map(|&c| (c - fit.value0 + fit.g.dot(fit.p0)) / len)
        .collect();
    cga_geometry::split_by_parallel_planes(face, normal, &offsets)
}

/// Cuts `face` in the texture space of `set` (see [`cut_along_uv`]); `None`
/// if that space has no room (no two spare UV sets) or the face is
/// degenerate there.
fn cut_in_texture_space(face: &Mesh, set: usize, axis: usize, cuts: &[f64]) -> Option<Vec<Mesh>> {
    // Spare sets for the 3D positions: unused ones, and `set` itself, whose
    // values the texture-space positions keep.
    let mut spare = (0..UV_SETS).filter(|&k| k == set || face.uvs[k].is_none());
    let (sa, sb) = (spare.next()?, spare.next()?);
    let uv: Vec<DVec2> = face.uvs[set].clone()?;
    // Twice the signed area of the texture-space polygon (outer loop).
    let outer = face.loop_corners(face.loops[0]);
    let n = outer.len();
    let area2: f64 = (0..n)
        .map(|i| {
            let (a, b) = (uv[outer.start + i], uv[outer.start + (i + 1) % n]);
            a.perp_dot(b)
        })
        .sum();
    let (lo, hi) = uv
        .iter()
        .fold((uv[0], uv[0]), |(lo, hi), &t| (lo.min(t), hi.max(t)));
    let extent = (hi - lo).max_element();
    let has_area = area2.abs() > 1e-12 * extent * extent;
    if !has_area {
        return None;
    }
    let mut m = face.clone();
    let corner_pos: Vec<DVec3> = face
        .corners
        .iter()
        .map(|&p| face.positions[p as usize])
        .collect();
    m.positions = uv.iter().map(|t| DVec3::new(t.x, t.y, 0.0)).collect();
    m.corners = (0..face.corners.len() as u32).collect();
    m.uvs[sa] = Some(corner_pos.iter().map(|p| DVec2::new(p.x, p.y)).collect());
    m.uvs[sb] = Some(corner_pos.iter().map(|p| DVec2::new(p.z, 0.0)).collect());
    let pieces = cga_geometry::split_along_axis(&m, axis, cuts);
    Some(
        pieces
            .into_iter()
            .map(|mut piece| {
                let n = piece.corners.len();
                let a = piece.uvs[sa].take().unwrap_or_else(|| vec![DVec2::ZERO; n]);
                let b = piece.uvs[sb].take().unwrap_or_else(|| vec![DVec2::ZERO; n]);
                let uv: Vec<DVec2> = piece
                    .corners
                    .iter()
                    .map(|&p| piece.positions[p as usize].truncate())
                    .collect();
                piece.positions = a
                    .iter()
                    .zip(&b)
                    .map(|(a, b)| DVec3::new(a.x, a.y, b.x))
                    .collect();
                piece.corners = (0..n as u32).collect();
                piece.uvs[set] = Some(uv);
                piece
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad_with_uvs(p: [DVec3; 4], uv: [DVec2; 4]) -> Mesh {
        let mut m = Mesh::polygon(&p);
        m.uvs[0] = Some(uv.to_vec());
        m
    }

    fn area(m: &Mesh) -> f64 {
        cga_geometry::measure::mesh_area(m)
    }

    #[test]
    fn affine_face_is_cut_by_planes() {
        // A 10 x 4 facade with u = x / 10.
        let p = [
            DVec3::ZERO,
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(10.0, 4.0, 0.0),
            DVec3::new(0.0, 4.0, 0.0),
        ];
        let uv = [
            DVec2::ZERO,
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        let slabs = cut_along_uv(&quad_with_uvs(p, uv), 0, 0, &[0.25, 0.5]);
        assert_eq!(slabs.len(), 3);
        let areas: Vec<f64> = slabs.iter().map(area).collect();
        assert!((areas[0] - 10.0).abs() < 1e-9, "{areas:?}");
        assert!((areas[1] - 10.0).abs() < 1e-9);
        assert!((areas[2] - 20.0).abs() < 1e-9);
        // The cut corners carry the cut value.
        let us: Vec<f64> = slabs[1].uvs[0]
            .as_ref()
            .unwrap()
            .iter()
            .map(|t| t.x)
            .collect();
        assert!(us
            .iter()
            .all(|&u| (u - 0.25).abs() < 1e-12 || (u - 0.5).abs() < 1e-12));
    }

    #[test]
    fn non_affine_face_is_cut_in_texture_space() {
        // A trapezoid: bottom edge 10 long, top edge 6 long, both u in [0, 1].
        let p = [
            DVec3::ZERO,
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(8.0, 0.0, -4.0),
            DVec3::new(2.0, 0.0, -4.0),
        ];
        let uv = [
            DVec2::ZERO,
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        let slabs = cut_along_uv(&quad_with_uvs(p, uv), 0, 0, &[0.5]);
        // The iso-line u = 0.5 joins the midpoints of both edges: (5, 0, 0)
        // and (5, 0, -4); both halves have area (5 + 3) / 2 * 4 = 16.
        for s in &slabs {
            assert_eq!(s.faces.len(), 1);
            assert!((area(s) - 16.0).abs() < 1e-9, "{}", area(s));
            let xs: Vec<f64> = s.positions.iter().map(|p| p.x).collect();
            assert!(xs.iter().filter(|&&x| (x - 5.0).abs() < 1e-12).count() == 2);
        }
    }

    #[test]
    fn png_alpha_detection() {
        let mut rgba = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x02\0\0\0\x02\x08\x06\0\0\0".to_vec();
        assert!(png_has_alpha(&rgba));
        rgba[25] = 2; // RGB
        assert!(!png_has_alpha(&rgba));
    }

    #[test]
    fn floating_tiles_span_the_extent() {
        assert!((floating_tile(2.0, 9.0) - 9.0 / 5.0).abs() < 1e-12);
        assert!((floating_tile(2.0, 0.5) - 0.5).abs() < 1e-12);
        assert!((floating_tile(-3.0, 9.0) + 3.0).abs() < 1e-12);
    }
}
