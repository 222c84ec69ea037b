//! Built-in functions and shape attributes that read the current shape
//! (`scope.sx`, `geometry.area`, `split.index`, `material.color.r`, `rand`, ...).
//! The resolver maps names to a [`ShapeFn`] once; evaluation is in `eval.rs`.

use crate::material_attr::MatField;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeFn {
    /// `scope.t{x|y|z}` (0..3), `scope.r{..}` (3..6), `scope.s{..}` (6..9).
    Scope(u8),
    ScopeElevation,
    /// `pivot.p{x|y|z}` (0..3), `pivot.o{..}` (3..6).
    Pivot(u8),
    SplitIndex,
    SplitTotal,
    CompSel,
    CompIndex,
    CompTotal,
    Seedian,
    TrimHorizontal,
    TrimVertical,
    Material(MatField),
    InitialShapeName,
    InitialShapeStartRule,
    /// `initialShape.origin.p{x|y|z}` (0..3), `initialShape.origin.o{..}` (3..6).
    InitialShapeOrigin(u8),
    Geometry(GeometryFn),
    /// `rand()`, `rand(max)`, `rand(min, max)`.
    Rand,
    /// `p(probability)`.
    P,
    /// `print(value)` as a function: prints and returns its argument.
    Print,
    /// Occlusion and context queries (`inside`, `overlaps`, `touches`,
    /// `contextCount`, `contextCompare`, `minimumDistance`).
    Context(ContextFn),
    /// File and coordinate functions (`file_fns.rs`).
    File(crate::file_fns::FileFn),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContextFn {
    Inside,
    Overlaps,
    Touches,
    ContextCount,
    ContextCompare,
    MinimumDistance,
}

/// Whether argument `pos` of the function `name` is a selector keyword
/// (`inside(all, "x")`, `convert(x, scope, world, pos, 0, 0, 0)`).
pub fn arg_is_selector(name: &str, pos: usize) -> bool {
    match name {
        "inside" | "overlaps" | "touches" | "contextCount" | "minimumDistance" => pos == 0,
        "contextCompare" => pos == 0 || pos == 2,
        "convert" => pos < 4,
        "geometry.area" | "geometry.angle" | "geometry.isOriented" => pos == 0,
        "geometry.du" | "geometry.dv" | "geometry.hasTags" | "geometry.tags" => pos == 1,
        "assetInfo" | "imageInfo" => pos == 1,
        "getGeoCoord" => pos == 0,
        "assetsSortSize" | "assetsSortRatio" | "imagesSortRatio" => pos == 1,
        "assetBestSize" | "assetApproxSize" | "assetFitSize" | "assetBestRatio"
        | "assetApproxRatio" | "imageBestRatio" | "imageApproxRatio" => pos == 1,
        "assetNamingInfo" | "assetNamingInfos" => pos == 1,
        "getMaterial" => pos < 2,
        _ => false,
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GeometryFn {
    Area,
    /// `geometry.isOriented(selector)`: some face matches the orientation.
    IsOriented,
    Volume,
    NVertices,
    NFaces,
    NEdges,
    NHoles,
    IsClosedSurface,
    IsPlanar,
    IsRectangular,
    IsConcave,
    BoundaryLength,
    Height,
    HasUVs,
    UMin,
    UMax,
    VMin,
    VMax,
    Du,
    Dv,
    /// `geometry.angle(maxSlope|azimuth|zenith)`.
    Angle,
    /// `geometry.materials()`: the names of the materials, in the order of
    /// `comp(m)`.
    Materials,
    /// `geometry.tags([query [, components]])`: the sorted tags.
    Tags,
    /// `geometry.hasTags([query [, components]])`.
    HasTags,
    /// `geometry.groups()`: the group names, in the order of `comp(g)`.
    Groups,
    /// `geometry.isInstanced()`: the geometry is an inserted asset, not
    /// changed since `i()` (only placed: `t`, `r`, `s` keep it).
    IsInstanced,
}

impl GeometryFn {
    /// Whether the function reads texture coordinates (`geometry.hasUVs`,
    /// `uMin`, `uMax`, `vMin`, `vMax`, `du`, `dv`).
    pub fn reads_uvs(self) -> bool {
        matches!(
            self,
            GeometryFn::HasUVs
                | GeometryFn::UMin
                | GeometryFn::UMax
                | GeometryFn::VMin
                | GeometryFn::VMax
                | GeometryFn::Du
                | GeometryFn::Dv
        )
    }
}

/// The shape function called `name` with `arity` arguments, if any.
pub fn lookup(name: &str, arity: usize) -> Option<ShapeFn> {
    let axis = |s: &str| match s {
        "x" => Some(0u8),
        "y" => Some(1),
        "z" => Some(2),
        _ => None,
    };
    let zero = arity == 0;
    // `t`, `r`, `s` (scope) or `p`, `o` (pivot, origin) and an axis: the
    // index of the component in that attribute's vector list.
    let component = |rest: &str, kinds: &[&str]| -> Option<u8> {
        // Two ASCII letters: a name such as `scope.ь` (two bytes, one
        // letter) is no component and must not be cut inside a letter.
        if !zero || rest.len() != 2 || !rest.is_ascii() {
            return None;
        }
        let (kind, ax) = rest.split_at(1);
        let k = kinds.iter().position(|&x| x == kind)? as u8;
        axis(ax).map(|a| 3 * k + a)
    };
    if let Some(rest) = name.strip_prefix("scope.") {
        if zero && rest == "elevation" {
            return Some(ShapeFn::ScopeElevation);
        }
        return component(rest, &["t", "r", "s"]).map(ShapeFn::Scope);
    }
    if let Some(rest) = name.strip_prefix("pivot.") {
        return component(rest, &["p", "o"]).map(ShapeFn::Pivot);
    }
    if let Some(rest) = name.strip_prefix("initialShape.origin.") {
        return component(rest, &["p", "o"]).map(ShapeFn::InitialShapeOrigin);
    }
    if name.starts_with("material.") {
        return if zero {
            MatField::parse(name).map(ShapeFn::Material)
        } else {
            None
        };
    }
    if let Some(rest) = name.strip_prefix("geometry.") {
        use GeometryFn::*;
        let (f, arities): (GeometryFn, &[usize]) = match rest {
            "area" => (Area, &[0, 1]),
            "isOriented" => (IsOriented, &[1]),
            "volume" => (Volume, &[0]),
            "nVertices" => (NVertices, &[0]),
            "nFaces" => (NFaces, &[0]),
            "nEdges" => (NEdges, &[0]),
            "nHoles" => (NHoles, &[0]),
            "isClosedSurface" => (IsClosedSurface, &[0]),
            "isPlanar" => (IsPlanar, &[0, 1]),
            "isRectangular" => (IsRectangular, &[0, 1]),
            "isConcave" => (IsConcave, &[0]),
            "boundaryLength" => (BoundaryLength, &[0]),
            "height" => (Height, &[0]),
            "hasUVs" => (HasUVs, &[0, 1]),
            "uMin" => (UMin, &[0, 1]),
            "uMax" => (UMax, &[0, 1]),
            "vMin" => (VMin, &[0, 1]),
            "vMax" => (VMax, &[0, 1]),
            "du" => (Du, &[1, 2]),
            "dv" => (Dv, &[1, 2]),
            "angle" => (Angle, &[1]),
            "materials" => (Materials, &[0]),
            "tags" => (Tags, &[0, 1, 2]),
            "hasTags" => (HasTags, &[0, 1, 2]),
            "groups" => (Groups, &[0]),
            "isInstanced" => (IsInstanced, &[0]),
            _ => return None,
        };
        return arities.contains(&arity).then_some(ShapeFn::Geometry(f));
    }
    let f = match (name, arity) {
        ("split.index", 0) => ShapeFn::SplitIndex,
        ("split.total", 0) => ShapeFn::SplitTotal,
        ("comp.sel", 0) => ShapeFn::CompSel,
        ("comp.index", 0) => ShapeFn::CompIndex,
        ("comp.total", 0) => ShapeFn::CompTotal,
        ("seedian", 0) => ShapeFn::Seedian,
        ("trim.horizontal", 0) => ShapeFn::TrimHorizontal,
        ("trim.vertical", 0) => ShapeFn::TrimVertical,
        ("initialShape.name", 0) => ShapeFn::InitialShapeName,
        ("initialShape.startRule", 0) => ShapeFn::InitialShapeStartRule,
        // Deprecated names CGA still reads (cga_changelog.md): the start
        // rule's old name (2010.1), and `uid`, replaced by getTreeKey
        // (2015.0).
        ("initialShape.symbol", 0) => ShapeFn::InitialShapeStartRule,
        ("uid", 0) => ShapeFn::File(crate::file_fns::FileFn::TreeKey),
        ("rand", 0..=2) => ShapeFn::Rand,
        ("p", 1) => ShapeFn::P,
        ("print", 1) => ShapeFn::Print,
        ("inside", 0..=2) => ShapeFn::Context(ContextFn::Inside),
        ("overlaps", 0..=2) => ShapeFn::Context(ContextFn::Overlaps),
        ("touches", 0..=2) => ShapeFn::Context(ContextFn::Touches),
        ("contextCount", 1..=3) => ShapeFn::Context(ContextFn::ContextCount),
        ("contextCompare", 1..=4) => ShapeFn::Context(ContextFn::ContextCompare),
        ("minimumDistance", 1..=3) => ShapeFn::Context(ContextFn::MinimumDistance),
        _ if crate::file_fns::lookup(name, arity).is_some() => {
            ShapeFn::File(crate::file_fns::lookup(name, arity)?)
        }
        _ => return None,
    };
    Some(f)
}

/// Shape attributes that `set` may write, with the same names as for reading.
pub fn is_settable(f: ShapeFn) -> bool {
    matches!(
        f,
        ShapeFn::Scope(_)
            | ShapeFn::Pivot(_)
            | ShapeFn::Seedian
            | ShapeFn::TrimHorizontal
            | ShapeFn::TrimVertical
            | ShapeFn::Material(_)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn looks_up_dotted_names() {
        assert_eq!(lookup("scope.sx", 0), Some(ShapeFn::Scope(6)));
        assert_eq!(lookup("scope.ry", 0), Some(ShapeFn::Scope(4)));
        assert_eq!(lookup("pivot.oz", 0), Some(ShapeFn::Pivot(5)));
        assert_eq!(
            lookup("geometry.area", 0),
            Some(ShapeFn::Geometry(GeometryFn::Area))
        );
        assert_eq!(lookup("geometry.area", 2), None);
        assert_eq!(lookup("rand", 2), Some(ShapeFn::Rand));
        assert_eq!(lookup("scope.qx", 0), None);
    }
}

mod eval {
    use std::sync::Arc;

    use cga_value::Value;

    use super::{GeometryFn, ShapeFn};
    use crate::derive::{Interp, RtError};
    use crate::expr::RExpr;
    use crate::selectors::{Frames, Selector};
    use crate::shape::{mat_to_euler, Shape};

    /// The orientation selector argument of `geometry.area` and
    /// `geometry.isOriented` (`all`/`surface`, quadrants, slopes, `side`).
    fn orientation_selector(v: &Value, at: &RExpr) -> Result<Selector, RtError> {
        let name = match v {
            Value::Str(s) => &**s,
            other => {
                return Err(RtError::new(
                    format!(
                        "expected an orientation selector, found {}",
                        crate::values::type_name(other)
                    ),
                    at.span,
                ))
            }
        };
        match name {
            "surface" => Ok(Selector::All),
            _ => Selector::parse(name)
                .filter(|s| s.is_orientation())
                .ok_or_else(|| {
                    RtError::new(
                        format!("`{name}` is not a face orientation selector (front, world.up, side, all, ...)"),
                        at.span,
                    )
                }),
        }
    }

    /// `geometry.tags([query [, components]])` and
    /// `geometry.hasTags([query [, components]])` (func_geometry.md): the
    /// alphabetically sorted tags of the components (all by default) that
    /// the query matches (all tags without one), or whether there are any.
    fn tags_fn(g: GeometryFn, args: &[Value], shape: &Shape, at: &RExpr) -> Result<Value, RtError> {
        use cga_geometry::tags::{collect_tags, TagQuery, TagTarget};
        let query = match args.first() {
            Some(Value::Str(q)) => TagQuery::parse(q),
            Some(other) => {
                return Err(RtError::new(
                    format!(
                        "the tag query must be a string, found {}",
                        crate::values::type_name(other)
                    ),
                    at.span,
                ))
            }
            None => TagQuery::all(),
        };
        let target = match args.get(1) {
            None => TagTarget::All,
            Some(Value::Str(s)) if matches!(&**s, "all" | "faces" | "edges" | "vertices") => {
                TagTarget::parse(s).unwrap_or(TagTarget::All)
            }
            Some(other) => {
                let msg = format!("expected all, faces, edges or vertices, found {other:?}");
                return Err(RtError::new(msg, at.span));
            }
        };
        // The stored mesh before its pending transform: tags do not move.
        let (mesh, _) = shape.geometry.raw();
        let tags = if mesh.may_have_tags() {
            collect_tags(mesh, &query, target)
        } else {
            Vec::new()
        };
        Ok(if g == GeometryFn::HasTags {
            Value::Bool(!tags.is_empty())
        } else {
            Value::StrArray(Arc::new(cga_value::Array::row(tags)))
        })
    }

    fn num(v: &Value, at: &RExpr) -> Result<f64, RtError> {
        match v {
            Value::Float(x) => Ok(*x),
            Value::Bool(b) => Ok(if *b { 1.0 } else { 0.0 }),
            other => Err(RtError::new(
                format!(
                    "expected a float, found {}",
                    crate::values::type_name(other)
                ),
                at.span,
            )),
        }
    }

    impl Interp<'_> {
        pub(crate) fn shape_fn(
            &mut self,
            f: ShapeFn,
            args: &[Value],
            shape: &Shape,
            at: &RExpr,
        ) -> Result<Value, RtError> {
            let fl = Value::Float;
            Ok(match f {
                ShapeFn::Scope(i) => {
                    let pivot = &shape.pivot;
                    let v = match i / 3 {
                        0 => pivot.to_local(shape.scope.frame.origin),
                        1 => shape.scope.rot,
                        _ => shape.scope.size,
                    };
                    fl(v[(i % 3) as usize])
                }
                ShapeFn::ScopeElevation => fl(shape.scope.frame.origin.y),
                ShapeFn::Pivot(i) => {
                    let init = &self.initial.pivot;
                    let v = if i < 3 {
                        init.to_local(shape.pivot.origin)
                    } else {
                        mat_to_euler(&(init.axes.transpose() * shape.pivot.axes))
                    };
                    fl(v[(i % 3) as usize])
                }
                ShapeFn::InitialShapeOrigin(i) => {
                    let init = &self.initial.pivot;
                    let v = if i < 3 {
                        init.origin
                    } else {
                        mat_to_euler(&init.axes)
                    };
                    fl(v[(i % 3) as usize])
                }
                ShapeFn::SplitIndex => fl(shape.split_index),
                ShapeFn::SplitTotal => fl(shape.split_total),
                ShapeFn::CompSel => Value::Str(
                    shape
                        .comp
                        .as_ref()
                        .map(|c| c.sel.clone())
                        .unwrap_or_else(|| Arc::from("")),
                ),
                ShapeFn::CompIndex => fl(shape.comp.as_ref().map_or(0.0, |c| c.index)),
                ShapeFn::CompTotal => fl(shape.comp.as_ref().map_or(0.0, |c| c.total)),
                ShapeFn::Seedian => fl(shape.seedian),
                ShapeFn::TrimHorizontal => Value::Bool(shape.trim.horizontal),
                ShapeFn::TrimVertical => Value::Bool(shape.trim.vertical),
                ShapeFn::Material(field) => {
                    let (mesh, _) = shape.geometry.raw();
                    let geometry_material = mesh
                        .faces
                        .first()
                        .map(|face| &mesh.materials[face.material as usize]);
                    shape.material.get(field, geometry_material)
                }
                ShapeFn::InitialShapeName => Value::Str(Arc::from(self.info.name.as_str())),
                ShapeFn::InitialShapeStartRule => {
                    Value::Str(Arc::from(self.info.start_rule.as_str()))
                }
                ShapeFn::Rand => {
                    let r = shape.next_random();
                    match args {
                        [] => fl(r),
                        [max] => fl(r * num(max, at)?),
                        [min, max] => {
                            let (a, b) = (num(min, at)?, num(max, at)?);
                            fl(a + r * (b - a))
                        }
                        _ => unreachable!("arity checked by the resolver"),
                    }
                }
                ShapeFn::P => {
                    let p = num(&args[0], at)?;
                    Value::Bool(if p <= 0.0 {
                        false
                    } else if p >= 1.0 {
                        true
                    } else {
                        shape.next_random() < p
                    })
                }
                ShapeFn::Print => {
                    self.out.prints.push(crate::values::to_text(&args[0]));
                    args[0].clone()
                }
                ShapeFn::Geometry(g) => self.geometry_fn(g, args, shape, at)?,
                ShapeFn::File(f) => self.file_fn(f, args, shape, at)?,
                ShapeFn::Context(c) => self.context_query(c, args, shape, at)?,
            })
        }

        /// The geometry functions that read the stored mesh as it is (tags,
        /// groups, whether it is an asset's).
        fn stored_mesh_fn(
            &mut self,
            g: GeometryFn,
            args: &[Value],
            shape: &Shape,
            at: &RExpr,
        ) -> Result<Value, RtError> {
            let (mesh, _) = shape.geometry.raw();
            Ok(match g {
                // The shape still holds the asset's own mesh (placing it
                // only changes the lazy map); any change made a new mesh.
                GeometryFn::IsInstanced => Value::Bool(self.assets.is_asset_mesh(mesh)),
                GeometryFn::Groups => {
                    let mut used = vec![false; mesh.groups.len()];
                    for f in &mesh.faces {
                        if let Some(u) = used.get_mut(f.group as usize) {
                            *u = true;
                        }
                    }
                    let names: Vec<Arc<str>> = mesh
                        .groups
                        .iter()
                        .zip(&used)
                        .filter(|(_, &u)| u)
                        .map(|(g, _)| Arc::from(g.as_str()))
                        .collect();
                    Value::StrArray(Arc::new(cga_value::Array::row(names)))
                }
                _ => tags_fn(g, args, shape, at)?,
            })
        }

        fn geometry_fn(
            &mut self,
            g: GeometryFn,
            args: &[Value],
            shape: &Shape,
            at: &RExpr,
        ) -> Result<Value, RtError> {
            use cga_geometry::measure as m;
            use cga_geometry::Topology;
            if matches!(
                g,
                GeometryFn::Tags
                    | GeometryFn::HasTags
                    | GeometryFn::Groups
                    | GeometryFn::IsInstanced
            ) {
                // No coordinates needed: the stored mesh serves.
                return self.stored_mesh_fn(g, args, shape, at);
            }
            // Measures are taken in object orientation and scale: scaling is
            // lazy, so the stored mesh alone would give wrong areas. Around
            // the scope's origin (see `Shape::oriented_transform`): none
            // depends on where the shape stands.
            let mesh = shape.oriented_mesh();
            let fl = Value::Float;
            let uv_set = |i: usize| -> Result<usize, RtError> {
                match args.get(i) {
                    Some(v) => {
                        let k = num(v, at)?;
                        if (0.0..10.0).contains(&k) {
                            Ok(k as usize)
                        } else {
                            Err(RtError::new(
                                format!("uv set {k} is not in [0, 9]"),
                                at.span,
                            ))
                        }
                    }
                    None => Ok(0),
                }
            };
            let tolerance =
                |i: usize| -> Result<f64, RtError> { args.get(i).map_or(Ok(0.0), |v| num(v, at)) };
            Ok(match g {
                GeometryFn::Area => match args.first() {
                    None => fl(m::mesh_area(&mesh)),
                    Some(sel) => {
                        let sel = orientation_selector(sel, at)?;
                        // The mesh is in object coordinates: read normals
                        // in the scope frame through the scope axes.
                        let frames =
                            Frames::for_scope(shape.scope.frame.axes, self.initial.pivot.axes);
                        let to_scope = shape.scope.frame.axes.transpose();
                        fl(m::mesh_area_where(&mesh, |_, n| {
                            frames.matches(sel, to_scope * n)
                        }))
                    }
                },
                GeometryFn::IsOriented => {
                    let sel = orientation_selector(&args[0], at)?;
                    let frames = Frames::for_scope(shape.scope.frame.axes, self.initial.pivot.axes);
                    let to_scope = shape.scope.frame.axes.transpose();
                    Value::Bool(
                        (0..mesh.faces.len())
                            .any(|f| frames.matches(sel, to_scope * m::face_normal(&mesh, f))),
                    )
                }
                GeometryFn::Volume => fl(if m::is_closed(&mesh) {
                    m::volume(&mesh).abs()
                } else {
                    0.0
                }),
                GeometryFn::NVertices | GeometryFn::NEdges => {
                    let counts = m::counts(&mesh, &Topology::new(&mesh));
                    fl(if g == GeometryFn::NVertices {
                        counts.vertices
                    } else {
                        counts.edges
                    } as f64)
                }
                GeometryFn::NFaces => fl(mesh.faces.len() as f64),
                GeometryFn::NHoles => fl(m::hole_count(&mesh) as f64),
                GeometryFn::IsClosedSurface => Value::Bool(m::is_closed(&mesh)),
                GeometryFn::IsPlanar => Value::Bool(m::is_planar(&mesh, tolerance(0)?)),
                GeometryFn::IsRectangular => Value::Bool(m::is_rectangular(&mesh, tolerance(0)?)),
                GeometryFn::IsConcave => Value::Bool(m::is_concave(&mesh)),
                GeometryFn::BoundaryLength => fl(m::boundary_length(&mesh, &Topology::new(&mesh))),
                GeometryFn::Height => fl(m::height(&mesh)),
                GeometryFn::HasUVs => Value::Bool(match args.first() {
                    Some(_) => mesh.uvs[uv_set(0)?].is_some(),
                    None => mesh.uvs.iter().any(|u| u.is_some()),
                }),
                GeometryFn::UMin | GeometryFn::UMax | GeometryFn::VMin | GeometryFn::VMax => {
                    let b = m::uv_bounds(&mesh, uv_set(0)?);
                    fl(b.map_or(0.0, |(lo, hi)| match g {
                        GeometryFn::UMin => lo.x,
                        GeometryFn::UMax => hi.x,
                        GeometryFn::VMin => lo.y,
                        _ => hi.y,
                    }))
                }
                GeometryFn::Materials => {
                    // Material slots that faces use, in slot order, as
                    // comp(m) makes its components.
                    let mut used = vec![false; mesh.materials.len()];
                    for f in &mesh.faces {
                        if let Some(u) = used.get_mut(f.material as usize) {
                            *u = true;
                        }
                    }
                    let names: Vec<std::sync::Arc<str>> = mesh
                        .materials
                        .iter()
                        .zip(&used)
                        .filter(|(_, &u)| u)
                        .map(|(m, _)| m.name.clone())
                        .collect();
                    Value::StrArray(std::sync::Arc::new(cga_value::Array::row(names)))
                }
                GeometryFn::Angle => {
                    let which = match &args[0] {
                        Value::Str(s) => s.clone(),
                        other => {
                            return Err(RtError::new(
                                format!(
                                    "expected maxSlope, azimuth or zenith, found {}",
                                    other.type_name()
                                ),
                                at.span,
                            ))
                        }
                    };
                    // The area-weighted normal of the geometry (the normal
                    // of a planar shape); its tilt from the y axis is the
                    // slope, and its horizontal part points down the slope.
                    let n = (0..mesh.faces.len())
                        .map(|f| m::face_normal(&mesh, f) * m::face_area(&mesh, f))
                        .fold(cga_geometry::DVec3::ZERO, |a, b| a + b)
                        .normalize_or_zero();
                    let slope = if n == cga_geometry::DVec3::ZERO {
                        0.0
                    } else {
                        n.y.clamp(-1.0, 1.0).acos().to_degrees()
                    };
                    match &*which {
                        "maxSlope" => fl(slope),
                        "zenith" => fl(90.0 - slope),
                        "azimuth" => {
                            // Clockwise from north (-z): east (+x) is 90.
                            let a = if n.x.abs() < 1e-12 && n.z.abs() < 1e-12 {
                                0.0
                            } else {
                                n.x.atan2(-n.z).to_degrees().rem_euclid(360.0)
                            };
                            fl(if a >= 360.0 { 0.0 } else { a })
                        }
                        other => {
                            return Err(RtError::new(
                                format!("unknown angle type `{other}`: expected maxSlope, azimuth or zenith"),
                                at.span,
                            ))
                        }
                    }
                }
                GeometryFn::Tags
                | GeometryFn::HasTags
                | GeometryFn::Groups
                | GeometryFn::IsInstanced => self.stored_mesh_fn(g, args, shape, at)?,
                GeometryFn::Du | GeometryFn::Dv => {
                    let set = uv_set(0)?;
                    let unit = matches!(args.get(1), Some(Value::Str(s)) if &**s == "unitSpace");
                    let range = m::uv_bounds(&mesh, set)
                        .map_or(cga_geometry::DVec2::ZERO, |(lo, hi)| hi - lo);
                    let range = if unit {
                        range * m::uv_unit_scale(&mesh, set).unwrap_or(cga_geometry::DVec2::ZERO)
                    } else {
                        range
                    };
                    fl(if g == GeometryFn::Du {
                        range.x
                    } else {
                        range.y
                    })
                }
            })
        }
    }
}
