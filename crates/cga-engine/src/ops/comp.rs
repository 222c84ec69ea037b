//! The component split `comp(f|e|fe|v|fv|g|m|h [, zUp|noAlign]) { selector
//! operator operations | ... }` and the comp function
//! `comp(...) { selector operator expression | ... }`.
//!
//! A shape's mesh is divided into components: faces, edges (shared edges
//! once, in the order of their first use), face edges (every edge of every
//! face), vertices (welded, in position order), face vertices, groups and
//! materials (the faces of each OBJ group / material slot that has faces)
//! and holes. The block's entries select components left to right; a
//! component taken by an entry is not offered to later ones. A head is a
//! selector keyword (see `crate::selectors`), an index, or a condition that
//! may combine keywords with `!`, `&&`, `||` and any expression on the
//! component (`geometry.area() > 1 && !inside`).
//!
//! Operators: `:` makes one shape per selected component, `=` one shape of
//! all of them, `=:` one shape per set of selected components connected
//! through shared edges (components without faces: through shared
//! vertices). `comp.sel` is the head as written, `comp.index`/`comp.total`
//! count the shapes of that entry.
//!
//! New shapes (with the default `zUp` alignment) get their pivot and scope
//! from the (first) component: faces have x along the first edge, z along
//! the face normal, the pivot on the first vertex and the scope the face's
//! bounding box in that frame (sz = 0); edges have x along the edge, z the
//! average normal of the faces around it, the pivot on the start vertex and
//! the scope (length, 0, 0); vertices have z along the average normal and
//! zero size; face edges and face vertices have y along the face normal and
//! z pointing out of the face. `noAlign` keeps pivot and scope orientation
//! and fits the scope to the component. Faces split with `:` get trim planes
//! at their shared edges (`crate::trim`).
//!
//! Heads that are conditions are evaluated once per component on the
//! component as a shape with the current shape's orientation (the `noAlign`
//! shape), so that `geometry.isOriented(top)` in a user function means the
//! same as the keyword `top`, and `geometry.area()` is the component's.
//!
//! The mesh is read in the current shape's scope-local coordinates, which
//! are metric (the scope axes are orthonormal), so every frame is first
//! built there and then mapped to object coordinates once.

use std::sync::Arc;

use cga_geometry::components::{
    face_frame, face_of_corner, frame_from_x_y, frame_from_x_z, frame_from_z, loop_of_corner,
    next_corner, prev_corner, reverse_keep_first, stored_normal, to_frame, SubmeshBuilder,
    UnionFind,
};
use cga_geometry::mesh::Face;
use cga_geometry::{measure, DMat3, DVec3, Mesh, Topology};
use cga_syntax::ast::{BinaryOp, BlockOp};
use cga_syntax::Span;
use cga_value::{Array, Value};

use super::transform::selector;
use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::{OpCall, RBlock, RExpr, RExprKind, RPart};
use crate::selectors::{Frames, RoofEdge, Selector};
use crate::shape::{CompInfo, Frame, Scope, Shape};
use crate::trim::{bisecting_plane, TrimPlane};
use crate::values as vs;

/// The comp function's array size limit (the reference's default).
pub const MAX_FN_COMPONENTS: usize = 100_000;

/// What `comp` splits into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Faces,
    Edges,
    FaceEdges,
    Vertices,
    FaceVertices,
    Groups,
    Materials,
    Holes,
}

impl Kind {
    fn parse(arg: &Arg) -> Result<Kind, RtError> {
        Ok(
            match selector(arg, &["f", "e", "fe", "v", "fv", "g", "m", "h"])? {
                "f" => Kind::Faces,
                "e" => Kind::Edges,
                "fe" => Kind::FaceEdges,
                "v" => Kind::Vertices,
                "fv" => Kind::FaceVertices,
                "g" => Kind::Groups,
                "m" => Kind::Materials,
                _ => Kind::Holes,
            },
        )
    }
}

/// Pivot and scope of the new shapes: aligned to the component (`zUp`,
/// the default) or kept (`noAlign`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Align {
    ZUp,
    NoAlign,
}

fn parse_align(arg: Option<&Arg>) -> Result<Align, RtError> {
    Ok(match arg {
        Some(a) if selector(a, &["zUp", "noAlign"])? == "noAlign" => Align::NoAlign,
        _ => Align::ZUp,
    })
}

/// One component: what part of the mesh it is.
#[derive(Clone, Copy, Debug)]
enum Item {
    /// Faces `face_list[start..start + len]` (a face, a group, a material).
    Faces { start: u32, len: u32 },
    /// Hole loop `lp` (index into `Mesh::loops`) of `face`.
    Hole { face: u32, lp: u32 },
    /// A unique edge of the topology.
    Edge(u32),
    /// The edge starting at `corner` of `face`.
    FaceEdge { face: u32, corner: u32 },
    /// A welded vertex and the first corner at it.
    Vertex { vid: u32, corner: u32 },
    /// The vertex at `corner` of `face`.
    FaceVertex { face: u32, corner: u32 },
}

/// The current shape's frames, for mapping built frames to object
/// coordinates and for `noAlign`.
#[derive(Clone, Copy)]
struct ParentFrames {
    scope: Scope,
    pivot: Frame,
}

/// The components of one mesh, with what selection needs (normals,
/// topology, roof classes) computed on first use.
pub(crate) struct Components {
    mesh: Arc<Mesh>,
    kind: Kind,
    items: Vec<Item>,
    face_list: Vec<u32>,
    face_normals: Vec<DVec3>,
    /// The normal each item is classified by (g/m: see `face_list`).
    item_normals: Vec<DVec3>,
    topo: Option<Topology>,
    /// Per unique edge: true if used by at most one face.
    edge_border: Vec<bool>,
    /// Per welded vertex: averaged normal, on a border edge.
    vertex_normal: Vec<DVec3>,
    vertex_border: Vec<bool>,
    roof: Option<Vec<Option<RoofEdge>>>,
    /// Per edge, for eaves: the roof face's use (see `roof_classes`).
    eave_use: Vec<Option<cga_geometry::topology::EdgeUse>>,
    frames: Frames,
    parent: ParentFrames,
    builder: SubmeshBuilder,
    /// `isTagged` results per query (see `tag_match`).
    tag_cache: Vec<TagMatch>,
}

/// Which faces, edges and vertices `isTagged(query)` matches by their own
/// tags or inherited ones (op_comp.md): a face by its tags, an edge by its
/// tags and those of its faces, a vertex by its tags and those of its
/// edges and faces. Edges and vertices are per unique edge / welded vertex
/// of the topology (empty when the component kind needs no topology and
/// no subcomponent is asked for).
struct TagMatch {
    query: String,
    /// Whether `edge` and `vertex` were computed.
    full: bool,
    face: Vec<bool>,
    edge: Vec<bool>,
    vertex: Vec<bool>,
}

/// The subcomponent argument of `isTagged(query, e|v)`.
#[derive(Clone, Copy, PartialEq, Eq)]
enum TagSub {
    Edges,
    Vertices,
}

impl Components {
    fn new(mesh: Arc<Mesh>, kind: Kind, shape: &Shape, object_axes: DMat3) -> Components {
        let face_normals: Vec<DVec3> = (0..mesh.faces.len())
            .map(|f| measure::face_normal(&mesh, f))
            .collect();
        let needs_topology = !matches!(
            kind,
            Kind::Faces | Kind::Groups | Kind::Materials | Kind::Holes
        );
        let mut c = Components {
            builder: SubmeshBuilder::new(&mesh),
            mesh,
            kind,
            items: Vec::new(),
            face_list: Vec::new(),
            face_normals,
            item_normals: Vec::new(),
            topo: None,
            edge_border: Vec::new(),
            vertex_normal: Vec::new(),
            vertex_border: Vec::new(),
            roof: None,
            eave_use: Vec::new(),
            frames: Frames::for_scope(shape.scope.frame.axes, object_axes),
            parent: ParentFrames {
                scope: shape.scope,
                pivot: shape.pivot,
            },
            tag_cache: Vec::new(),
        };
        if needs_topology {
            c.topology();
        }
        c.collect_items();
        c
    }

    fn len(&self) -> usize {
        self.items.len()
    }

    /// The topology, with per-edge and per-vertex facts (computed once).
    fn topology(&mut self) -> &Topology {
        if self.topo.is_none() {
            let mesh = &*self.mesh;
            let topo = Topology::new(mesh);
            let n_edges = topo.edges.len();
            let mut edge_border = vec![false; n_edges];
            for (e, b) in edge_border.iter_mut().enumerate() {
                let uses = topo.edge_uses(e);
                // "Connected to only one face": uses by one face only (an
                // edge shape's two corners use its edge twice).
                *b = uses.iter().all(|u| u.face == uses[0].face);
            }
            let nv = topo.weld.count;
            let mut vertex_normal = vec![DVec3::ZERO; nv];
            let mut last_face = vec![u32::MAX; nv];
            for f in 0..mesh.faces.len() {
                for &l in mesh.face_loops(f) {
                    for &p in mesh.loop_indices(l) {
                        let v = topo.weld.id[p as usize] as usize;
                        if last_face[v] != f as u32 {
                            last_face[v] = f as u32;
                            vertex_normal[v] += self.face_normals[f];
                        }
                    }
                }
            }
            for n in &mut vertex_normal {
                *n = n.normalize_or_zero();
            }
            let mut vertex_border = vec![false; nv];
            for (e, edge) in topo.edges.iter().enumerate() {
                if edge_border[e] {
                    vertex_border[edge.v[0] as usize] = true;
                    vertex_border[edge.v[1] as usize] = true;
                }
            }
            self.edge_border = edge_border;
            self.vertex_normal = vertex_normal;
            self.vertex_border = vertex_border;
            self.topo = Some(topo);
        }
        self.topo.as_ref().expect("just computed")
    }

    fn collect_items(&mut self) {
        let mesh = self.mesh.clone();
        let n_faces = mesh.faces.len();
        match self.kind {
            Kind::Faces => {
                self.face_list = (0..n_faces as u32).collect();
                self.items.reserve_exact(n_faces);
                self.item_normals.reserve_exact(n_faces);
                for f in 0..n_faces as u32 {
                    self.items.push(Item::Faces { start: f, len: 1 });
                    self.item_normals.push(self.face_normals[f as usize]);
                }
            }
            Kind::Groups | Kind::Materials => {
                let slots = if self.kind == Kind::Groups {
                    mesh.groups.len()
                } else {
                    mesh.materials.len()
                };
                let slot_of = |f: &Face| {
                    if self.kind == Kind::Groups {
                        f.group as usize
                    } else {
                        f.material as usize
                    }
                };
                let mut by_slot: Vec<Vec<u32>> = vec![Vec::new(); slots];
                for (i, f) in mesh.faces.iter().enumerate() {
                    if let Some(list) = by_slot.get_mut(slot_of(f)) {
                        list.push(i as u32);
                    }
                }
                // Slots without faces are not components.
                for list in by_slot.into_iter().filter(|l| !l.is_empty()) {
                    let start = self.face_list.len() as u32;
                    self.face_list.extend_from_slice(&list);
                    self.items.push(Item::Faces {
                        start,
                        len: list.len() as u32,
                    });
                    self.item_normals.push(self.face_normals[list[0] as usize]);
                }
            }
            Kind::Holes => {
                for f in 0..n_faces {
                    let face = mesh.faces[f];
                    for lp in face.first_loop + 1..face.first_loop + face.loop_count {
                        self.items.push(Item::Hole { face: f as u32, lp });
                        self.item_normals.push(self.face_normals[f]);
                    }
                }
            }
            Kind::Edges => {
                let n = self.topology().edges.len();
                for e in 0..n {
                    self.items.push(Item::Edge(e as u32));
                    let n = self.edge_normal(e);
                    self.item_normals.push(n);
                }
            }
            Kind::FaceEdges | Kind::FaceVertices => {
                for f in 0..n_faces {
                    for &l in mesh.face_loops(f) {
                        for c in mesh.loop_corners(l) {
                            let (face, corner) = (f as u32, c as u32);
                            let item = if self.kind == Kind::FaceEdges {
                                Item::FaceEdge { face, corner }
                            } else {
                                Item::FaceVertex { face, corner }
                            };
                            self.items.push(item);
                            let frame = self.item_frame(item, false);
                            self.item_normals.push(frame.1.z_axis);
                        }
                    }
                }
            }
            Kind::Vertices => {
                // Welded ids are numbered in position order; vertices no
                // face uses are not components.
                let topo = self.topology();
                let mut first_corner = vec![u32::MAX; topo.weld.count];
                for (c, &p) in mesh.corners.iter().enumerate() {
                    let v = topo.weld.id[p as usize] as usize;
                    if first_corner[v] == u32::MAX {
                        first_corner[v] = c as u32;
                    }
                }
                for (vid, corner) in first_corner.into_iter().enumerate() {
                    if corner != u32::MAX {
                        self.items.push(Item::Vertex {
                            vid: vid as u32,
                            corner,
                        });
                        self.item_normals.push(self.vertex_normal[vid]);
                    }
                }
            }
        }
    }

    /// Average normal of the distinct faces using edge `e`.
    fn edge_normal(&self, e: usize) -> DVec3 {
        let topo = self.topo.as_ref().expect("edges need the topology");
        let mut acc = DVec3::ZERO;
        let mut last = u32::MAX;
        for u in topo.edge_uses(e) {
            if u.face != last {
                last = u.face;
                acc += self.face_normals[u.face as usize];
            }
        }
        acc.try_normalize().unwrap_or_else(|| {
            topo.edge_uses(e)
                .first()
                .map_or(DVec3::ZERO, |u| self.face_normals[u.face as usize])
        })
    }

    fn faces_of(&self, start: u32, len: u32) -> &[u32] {
        &self.face_list[start as usize..(start + len) as usize]
    }

    /// True if component `k` satisfies the selector keyword `sel`. Groups
    /// and materials satisfy it if one of their faces does.
    fn matches(&mut self, sel: Selector, k: usize) -> bool {
        let item = self.items[k];
        match sel {
            Selector::All => true,
            Selector::IsTagged => false,
            Selector::Border | Selector::Inside => {
                let want = sel == Selector::Border;
                match item {
                    Item::Hole { .. } => false,
                    Item::Faces { start, len } => {
                        self.topology();
                        self.faces_of(start, len)
                            .iter()
                            .any(|&f| self.face_is_border(f as usize) == want)
                    }
                    Item::Edge(e) => self.edge_border[e as usize] == want,
                    Item::FaceEdge { corner, .. } => {
                        let e = self.topology().edge_of_corner[corner as usize];
                        e != u32::MAX && self.edge_border[e as usize] == want
                    }
                    Item::Vertex { vid, .. } => self.vertex_border[vid as usize] == want,
                    Item::FaceVertex { corner, .. } => {
                        let p = self.mesh.corners[corner as usize] as usize;
                        let v = self.topology().weld.id[p] as usize;
                        self.vertex_border[v] == want
                    }
                }
            }
            Selector::Roof(r) => match item {
                Item::Edge(e) => self.roof_classes()[e as usize] == Some(r),
                _ => false,
            },
            _ => match item {
                Item::Faces { start, len } if len > 1 => self
                    .faces_of(start, len)
                    .iter()
                    .any(|&f| self.frames.matches(sel, self.face_normals[f as usize])),
                _ => self.frames.matches(sel, self.item_normals[k]),
            },
        }
    }

    /// The index in `tag_cache` of the `TagMatch` of `query` (computed
    /// once per comp), with edges and vertices if `full`.
    fn tag_match(&mut self, query: &str, full: bool) -> usize {
        let found = self
            .tag_cache
            .iter()
            .position(|t| t.query == query && (t.full || !full));
        if let Some(i) = found {
            return i;
        }
        let q = cga_geometry::TagQuery::parse(query);
        let mesh = self.mesh.clone();
        // Per tag set of the table: does it match?
        let set_ok: Vec<bool> = mesh.tags.iter().map(|s| s.matches(&q)).collect();
        let ok = |i: u32| set_ok.get(i as usize).copied().unwrap_or(false);
        let face: Vec<bool> = mesh.faces.iter().map(|f| ok(f.tags)).collect();
        let (mut edge, mut vertex) = (Vec::new(), Vec::new());
        if full {
            let topo = self.topology();
            edge = vec![false; topo.edges.len()];
            for (e, hit) in edge.iter_mut().enumerate() {
                *hit = topo
                    .edge_uses(e)
                    .iter()
                    .any(|u| face[u.face as usize] || ok(mesh.edge_tag_index(u.corner as usize)));
            }
            vertex = vec![false; topo.weld.count];
            for (f, &face_ok) in face.iter().enumerate() {
                for &l in mesh.face_loops(f) {
                    for c in mesh.loop_corners(l) {
                        let v = topo.weld.id[mesh.corners[c] as usize] as usize;
                        if face_ok || ok(mesh.vertex_tag_index(c)) {
                            vertex[v] = true;
                        }
                    }
                }
            }
            for (e, ed) in topo.edges.iter().enumerate() {
                if edge[e] {
                    vertex[ed.v[0] as usize] = true;
                    vertex[ed.v[1] as usize] = true;
                }
            }
        }
        self.tag_cache.push(TagMatch {
            query: query.to_string(),
            full,
            face,
            edge,
            vertex,
        });
        self.tag_cache.len() - 1
    }

    /// `isTagged(query [, sub])` for component `k` (see `TagMatch`): with
    /// `sub`, a component matches if one of its edges or vertices does.
    fn is_tagged(&mut self, k: usize, query: &str, sub: Option<TagSub>) -> bool {
        if !self.mesh.may_have_tags() {
            return false;
        }
        let item = self.items[k];
        let full = sub.is_some() || !matches!(item, Item::Faces { .. } | Item::Hole { .. });
        let i = self.tag_match(query, full);
        let t = &self.tag_cache[i];
        let mesh = &*self.mesh;
        let topo = self.topo.as_ref();
        let vid = |c: usize| topo.map(|t| t.weld.id[mesh.corners[c] as usize] as usize);
        let edge_of = |c: usize| {
            topo.map(|t| t.edge_of_corner[c])
                .filter(|&e| e != u32::MAX)
                .map(|e| e as usize)
        };
        let edge_hit =
            |e: Option<usize>| e.is_some_and(|e| t.edge.get(e).copied().unwrap_or(false));
        let vertex_hit =
            |v: Option<usize>| v.is_some_and(|v| t.vertex.get(v).copied().unwrap_or(false));
        // A face by its own tags, or by one of its edges or vertices.
        let face_hit = |f: usize| match sub {
            None => t.face[f],
            Some(TagSub::Edges) => mesh
                .face_loops(f)
                .iter()
                .any(|&l| mesh.loop_corners(l).any(|c| edge_hit(edge_of(c)))),
            Some(TagSub::Vertices) => mesh
                .face_loops(f)
                .iter()
                .any(|&l| mesh.loop_corners(l).any(|c| vertex_hit(vid(c)))),
        };
        match item {
            Item::Faces { start, len } => self
                .faces_of(start, len)
                .iter()
                .any(|&f| face_hit(f as usize)),
            Item::Hole { face, lp } => match sub {
                None => t.face[face as usize],
                Some(_) => {
                    let l = mesh.loops[lp as usize];
                    mesh.loop_corners(l).any(|c| match sub {
                        Some(TagSub::Edges) => edge_hit(edge_of(c)),
                        _ => vertex_hit(vid(c)),
                    })
                }
            },
            Item::Edge(e) => match sub {
                Some(TagSub::Vertices) => topo.is_some_and(|tp| {
                    let ed = tp.edges[e as usize];
                    vertex_hit(Some(ed.v[0] as usize)) || vertex_hit(Some(ed.v[1] as usize))
                }),
                _ => edge_hit(Some(e as usize)),
            },
            Item::FaceEdge { corner, face } => {
                let c = corner as usize;
                match sub {
                    Some(TagSub::Vertices) => {
                        let l = loop_of_corner(mesh, face as usize, c);
                        let r = mesh.loop_corners(l);
                        let n = if c + 1 == r.end { r.start } else { c + 1 };
                        vertex_hit(vid(c)) || vertex_hit(vid(n))
                    }
                    // A zero-length face edge has no unique edge: its face
                    // and its own tags decide.
                    _ => match edge_of(c) {
                        Some(e) => edge_hit(Some(e)),
                        None => t.face[face as usize],
                    },
                }
            }
            Item::Vertex { vid: v, .. } => vertex_hit(Some(v as usize)),
            Item::FaceVertex { corner, .. } => vertex_hit(vid(corner as usize)),
        }
    }

    /// A face is a border face if one of its edges is a border edge.
    fn face_is_border(&self, f: usize) -> bool {
        let topo = self.topo.as_ref().expect("computed by the caller");
        self.mesh.face_loops(f).iter().any(|&l| {
            self.mesh.loop_corners(l).any(|c| {
                let e = topo.edge_of_corner[c];
                e != u32::MAX && self.edge_border[e as usize]
            })
        })
    }

    /// Roof edge classes of all unique edges (op_comp.md, "Roof Edges"),
    /// from the geometry alone (`cga_geometry::roof_edges`, which agrees with
    /// the classes `cga_geometry::roof` gives the roofs it builds): faces
    /// facing up are roof faces, faces facing down bases; eaves are the
    /// lowest horizontal edges of one roof face (and bases), valleys the
    /// concave edges between two roof faces, hips the others touching an
    /// eave, ridges the rest. "Up" is the world's up direction.
    fn roof_classes(&mut self) -> &[Option<RoofEdge>] {
        if self.roof.is_none() {
            use cga_geometry::roof::RoofEdgeKind as K;
            self.topology();
            let topo = self.topo.as_ref().expect("just computed");
            let up = self.parent.scope.frame.axes.transpose() * DVec3::Y;
            let c = cga_geometry::roof_edges::classify_roof_edges(
                &self.mesh,
                topo,
                &self.face_normals,
                up,
            );
            let class = c
                .kinds
                .iter()
                .map(|k| match k {
                    K::Eave => Some(RoofEdge::Eave),
                    K::Hip => Some(RoofEdge::Hip),
                    K::Valley => Some(RoofEdge::Valley),
                    K::Ridge => Some(RoofEdge::Ridge),
                    K::Other => None,
                })
                .collect();
            self.eave_use = c.eave_use;
            self.roof = Some(class);
        }
        self.roof.as_deref().expect("just computed")
    }

    /// The use an edge component takes its direction from: an eave's roof
    /// face (eaves run counter-clockwise around the footprint), else the
    /// first face using the edge.
    fn edge_use(&self, e: usize) -> cga_geometry::topology::EdgeUse {
        let topo = self.topo.as_ref().expect("edges need the topology");
        self.eave_use
            .get(e)
            .copied()
            .flatten()
            .unwrap_or(topo.edge_uses(e)[0])
    }

    /// The unit direction in face `f`'s plane, perpendicular to the edge
    /// starting at `corner`, pointing into the face (left of the edge seen
    /// along the normal, for outer loops and holes alike).
    fn inward(&self, f: usize, corner: usize) -> DVec3 {
        let (a, b) = self.corner_edge(corner);
        self.face_normals[f].cross(b - a).normalize_or_zero()
    }

    /// The positions of the edge from `corner` to the next corner of its loop.
    fn corner_edge(&self, corner: usize) -> (DVec3, DVec3) {
        let mesh = &*self.mesh;
        let next = next_corner(mesh, corner);
        (
            mesh.positions[mesh.corners[corner] as usize],
            mesh.positions[mesh.corners[next] as usize],
        )
    }

    /// The frame (origin, axes; parent scope-local coordinates) of a
    /// component. `upward`: orient edges so that they end higher than they
    /// start (roof edges hip, valley, ridge).
    fn item_frame(&self, item: Item, upward: bool) -> (DVec3, DMat3) {
        let mesh = &*self.mesh;
        let pos = |p: u32| mesh.positions[p as usize];
        match item {
            Item::Faces { start, .. } => {
                let f = self.face_list[start as usize] as usize;
                let l = mesh.outer_loop(f);
                face_frame(
                    mesh.loop_points(l),
                    self.face_normals[f],
                    stored_normal(mesh, l.start as usize),
                )
            }
            Item::Hole { face, lp } => {
                let l = mesh.loops[lp as usize];
                let mut pts: Vec<DVec3> = mesh.loop_points(l).collect();
                reverse_keep_first(&mut pts);
                face_frame(pts, self.face_normals[face as usize], None)
            }
            Item::Edge(e) => {
                // The direction of the edge's first use (or an eave's roof face).
                let u = self.edge_use(e as usize);
                let c = u.corner as usize;
                let (mut a, mut b) = (
                    pos(mesh.corners[c]),
                    pos(mesh.corners[next_corner(mesh, c)]),
                );
                if upward {
                    let up = self.parent.scope.frame.axes.transpose() * DVec3::Y;
                    if b.dot(up) < a.dot(up) {
                        std::mem::swap(&mut a, &mut b);
                    }
                }
                (a, frame_from_x_z(b - a, self.edge_normal(e as usize)))
            }
            Item::FaceEdge { face, corner } => {
                let (a, b) = self.corner_edge(corner as usize);
                let n = self.face_normal_or_stored(face as usize, corner as usize);
                (a, frame_from_x_y(b - a, n))
            }
            Item::Vertex { vid, corner } => {
                let z = self.vertex_normal[vid as usize];
                (pos(mesh.corners[corner as usize]), frame_from_z(z))
            }
            Item::FaceVertex { face, corner } => {
                let c = corner as usize;
                let p = pos(mesh.corners[c]);
                let next = pos(mesh.corners[next_corner(mesh, c)]);
                let prev = pos(mesh.corners[prev_corner(mesh, c)]);
                let n = self.face_normal_or_stored(face as usize, c);
                let l = loop_of_corner(mesh, face as usize, c);
                let tangent = if l.len == 2 {
                    // An edge shape: the tangent is the edge's direction.
                    pos(mesh.corners[l.start as usize + 1]) - pos(mesh.corners[l.start as usize])
                } else {
                    let t = (p - prev).normalize_or_zero() + (next - p).normalize_or_zero();
                    if t.length_squared() > 1e-20 {
                        t
                    } else {
                        next - p
                    }
                };
                (p, frame_from_x_y(tangent, n))
            }
        }
    }

    fn face_normal_or_stored(&self, f: usize, corner: usize) -> DVec3 {
        let n = self.face_normals[f];
        if n != DVec3::ZERO {
            n
        } else {
            stored_normal(&self.mesh, corner).unwrap_or(DVec3::ZERO)
        }
    }

    /// The trim planes of face `f` (parent scope-local coordinates): one
    /// per edge shared with another face (classified when applied, against
    /// the pivot then in force: `crate::trim`).
    fn trim_planes(&mut self, f: usize) -> Vec<TrimPlane> {
        self.topology();
        let topo = self.topo.as_ref().expect("just computed");
        let mesh = &*self.mesh;
        let mut out: Vec<TrimPlane> = Vec::new();
        if self.face_normals[f] == DVec3::ZERO {
            return out;
        }
        for &l in mesh.face_loops(f) {
            for c in mesh.loop_corners(l) {
                let e = topo.edge_of_corner[c];
                if e == u32::MAX {
                    continue;
                }
                let Some(other) = topo
                    .edge_uses(e as usize)
                    .iter()
                    .find(|u| u.face as usize != f)
                else {
                    continue;
                };
                if self.face_normals[other.face as usize] == DVec3::ZERO {
                    continue;
                }
                let (a, b) = self.corner_edge(c);
                let m_face = self.inward(f, c);
                let m_other = self.inward(other.face as usize, other.corner as usize);
                let Some(plane) = bisecting_plane(a, b, m_face, m_other) else {
                    continue;
                };
                // Collinear edges with the same neighbour give the same plane.
                let dup = out.iter().any(|q| {
                    q.normal.dot(plane.normal) > 1.0 - 1e-12
                        && (q.normal.dot(plane.point - q.point)).abs() < 1e-9
                });
                if !dup {
                    out.push(plane);
                }
            }
        }
        out
    }

    /// Fills `shape` (a copy of the current shape) with the components
    /// `set`: geometry, pivot and scope; trim planes if `trim` (faces split
    /// with `:`).
    fn fill_shape(
        &mut self,
        shape: &mut Shape,
        set: &[u32],
        align: Align,
        trim: bool,
        upward: bool,
    ) {
        let first = self.items[set[0] as usize];
        let (origin, axes) = match align {
            Align::ZUp => self.item_frame(first, upward),
            Align::NoAlign => (DVec3::ZERO, DMat3::IDENTITY),
        };
        let points = matches!(
            self.kind,
            Kind::Edges | Kind::FaceEdges | Kind::Vertices | Kind::FaceVertices
        );
        let mut mesh = self.builder.begin(&self.mesh, points);
        // Room for the corners of the faces taken (edges and vertices are a
        // corner or two), so the component's arrays are allocated once.
        let corners: usize = set
            .iter()
            .map(|&k| match self.items[k as usize] {
                Item::Faces { start, len } => self.face_list
                    [start as usize..(start + len) as usize]
                    .iter()
                    .flat_map(|&f| self.mesh.face_loops(f as usize))
                    .map(|l| l.len as usize)
                    .sum(),
                Item::Hole { lp, .. } => self.mesh.loops[lp as usize].len as usize,
                _ => 2,
            })
            .sum();
        mesh.reserve(corners);
        for &k in set {
            let item = self.items[k as usize];
            self.add_item(&mut mesh, item, upward);
        }
        self.builder.finish(&self.mesh, &mut mesh);
        let (lo, hi) = to_frame(&mut mesh, origin, axes);

        let p = self.parent;
        let obj_axes = p.scope.frame.axes * axes;
        let obj_origin = p.scope.frame.to_object(origin);
        let pivot = match align {
            Align::ZUp => Frame {
                origin: obj_origin,
                axes: obj_axes,
            },
            Align::NoAlign => p.pivot,
        };
        let mut scope = Scope {
            frame: Frame {
                origin: obj_origin + obj_axes * lo,
                axes: obj_axes,
            },
            size: hi - lo,
            rot: DVec3::ZERO,
        };
        scope.set_axes(&pivot.axes, obj_axes);
        shape.pivot = pivot;
        shape.scope = scope;
        shape.set_local_mesh(mesh);
        shape.trim.planes = None;
        if trim {
            if let Item::Faces { start, len: 1 } = first {
                let f = self.face_list[start as usize] as usize;
                let planes = self.trim_planes(f);
                if !planes.is_empty() {
                    let frame = p.scope.frame;
                    let planes: Vec<TrimPlane> = planes
                        .into_iter()
                        .map(|t| TrimPlane {
                            point: frame.to_object(t.point),
                            normal: frame.axes * t.normal,
                            edge: frame.axes * t.edge,
                        })
                        .collect();
                    shape.trim.planes = Some(Arc::from(planes));
                }
            }
        }
    }

    fn add_item(&mut self, out: &mut Mesh, item: Item, upward: bool) {
        let mesh = self.mesh.clone();
        match item {
            Item::Faces { start, len } => {
                for i in start..start + len {
                    let f = self.face_list[i as usize] as usize;
                    self.builder.add_face(&mesh, out, f);
                }
            }
            Item::Hole { face, lp } => {
                self.builder
                    .add_hole(&mesh, out, face as usize, lp as usize)
            }
            Item::Edge(e) => {
                let first = self.edge_use(e as usize);
                let c = first.corner as usize;
                let mut corners = [c, next_corner(&mesh, c)];
                if upward {
                    let up = self.parent.scope.frame.axes.transpose() * DVec3::Y;
                    let h = |c: usize| mesh.positions[mesh.corners[c] as usize].dot(up);
                    if h(corners[1]) < h(corners[0]) {
                        corners.swap(0, 1);
                    }
                }
                let n = self.edge_normal(e as usize);
                self.builder
                    .add_points(&mesh, out, &corners, first.face as usize, n);
            }
            Item::FaceEdge { face, corner } => {
                let c = corner as usize;
                let n = self.item_frame(item, false).1.z_axis;
                self.builder
                    .add_points(&mesh, out, &[c, next_corner(&mesh, c)], face as usize, n);
            }
            Item::Vertex { vid, corner } => {
                // The first corner at the vertex gives its attributes.
                let c = corner as usize;
                let face = face_of_corner(&mesh, c);
                let n = self.vertex_normal[vid as usize];
                self.builder.add_points(&mesh, out, &[c], face, n);
            }
            Item::FaceVertex { face, corner } => {
                let n = self.item_frame(item, false).1.z_axis;
                self.builder
                    .add_points(&mesh, out, &[corner as usize], face as usize, n);
            }
        }
    }

    /// The connected sets of the selected components `sel` (ascending): two
    /// are connected if their faces share an edge; components without faces
    /// if they share a vertex (vertices: if an edge joins them). Sets are
    /// ordered by their first component.
    fn connected_sets(&mut self, sel: &[u32]) -> Vec<Vec<u32>> {
        self.topology();
        let topo = self.topo.as_ref().expect("just computed");
        let mesh = &*self.mesh;
        let mut dsu = UnionFind::new(sel.len());
        match self.kind {
            Kind::Faces | Kind::Groups | Kind::Materials | Kind::Holes => {
                // The selected component each face belongs to.
                let mut owner = vec![u32::MAX; mesh.faces.len()];
                for (i, &k) in sel.iter().enumerate() {
                    match self.items[k as usize] {
                        Item::Faces { start, len } => {
                            for &f in &self.face_list[start as usize..(start + len) as usize] {
                                owner[f as usize] = i as u32;
                            }
                        }
                        Item::Hole { face, .. } => owner[face as usize] = i as u32,
                        _ => {}
                    }
                }
                if self.kind == Kind::Holes {
                    // Holes connect through shared vertices of their loops.
                    let mut at_vertex = vec![u32::MAX; topo.weld.count];
                    for (i, &k) in sel.iter().enumerate() {
                        if let Item::Hole { lp, .. } = self.items[k as usize] {
                            for &p in mesh.loop_indices(mesh.loops[lp as usize]) {
                                let v = topo.weld.id[p as usize] as usize;
                                if at_vertex[v] == u32::MAX {
                                    at_vertex[v] = i as u32;
                                } else {
                                    dsu.union(at_vertex[v] as usize, i);
                                }
                            }
                        }
                    }
                } else {
                    for e in 0..topo.edges.len() {
                        let mut first = u32::MAX;
                        for u in topo.edge_uses(e) {
                            let o = owner[u.face as usize];
                            if o == u32::MAX {
                                continue;
                            }
                            if first == u32::MAX {
                                first = o;
                            } else {
                                dsu.union(first as usize, o as usize);
                            }
                        }
                    }
                }
            }
            Kind::Edges | Kind::FaceEdges | Kind::FaceVertices => {
                let mut at_vertex = vec![u32::MAX; topo.weld.count];
                for (i, &k) in sel.iter().enumerate() {
                    let verts: [Option<u32>; 2] = match self.items[k as usize] {
                        Item::Edge(e) => {
                            let ed = topo.edges[e as usize];
                            [Some(ed.v[0]), Some(ed.v[1])]
                        }
                        Item::FaceEdge { corner, .. } => {
                            let c = corner as usize;
                            let id = |c: usize| topo.weld.id[mesh.corners[c] as usize];
                            [Some(id(c)), Some(id(next_corner(mesh, c)))]
                        }
                        Item::FaceVertex { corner, .. } => [
                            Some(topo.weld.id[mesh.corners[corner as usize] as usize]),
                            None,
                        ],
                        _ => [None, None],
                    };
                    for v in verts.into_iter().flatten() {
                        let v = v as usize;
                        if at_vertex[v] == u32::MAX {
                            at_vertex[v] = i as u32;
                        } else {
                            dsu.union(at_vertex[v] as usize, i);
                        }
                    }
                }
            }
            Kind::Vertices => {
                let mut index_of = vec![u32::MAX; topo.weld.count];
                for (i, &k) in sel.iter().enumerate() {
                    if let Item::Vertex { vid, .. } = self.items[k as usize] {
                        index_of[vid as usize] = i as u32;
                    }
                }
                for edge in &topo.edges {
                    let (a, b) = (index_of[edge.v[0] as usize], index_of[edge.v[1] as usize]);
                    if a != u32::MAX && b != u32::MAX {
                        dsu.union(a as usize, b as usize);
                    }
                }
            }
        }
        let mut set_of_root = vec![u32::MAX; sel.len()];
        let mut sets: Vec<Vec<u32>> = Vec::new();
        for (i, &k) in sel.iter().enumerate() {
            let r = dsu.find(i);
            if set_of_root[r] == u32::MAX {
                set_of_root[r] = sets.len() as u32;
                sets.push(Vec::new());
            }
            sets[set_of_root[r] as usize].push(k);
        }
        sets
    }
}

// ----- selection -----

/// One entry of a comp block, flattened.
struct Entry<'b, T> {
    head: &'b RExpr,
    op: BlockOp,
    body: &'b T,
}

fn entries<T>(block: &RBlock<T>) -> Result<Vec<Entry<'_, T>>, RtError> {
    let mut out = Vec::with_capacity(block.parts.len());
    for part in &block.parts {
        match part {
            RPart::Entry { head, op, body, .. } => out.push(Entry {
                head,
                op: *op,
                body,
            }),
            RPart::Group(g) => {
                return Err(RtError::new(
                    "a comp block has no groups: write `selector : operations | ...`",
                    g.span,
                ))
            }
            RPart::Unlabeled { span, .. } => {
                return Err(RtError::new(
                    "a comp entry needs a selector: `selector : operations`",
                    *span,
                ))
            }
        }
    }
    if block.repeat {
        return Err(RtError::new(
            "a comp block cannot be repeated (`}*`)",
            block.span,
        ));
    }
    Ok(out)
}

/// The selector text (for `comp.sel`) and the selection expression of a head.
fn split_head(head: &RExpr) -> (Arc<str>, &RExpr) {
    match &head.kind {
        RExprKind::CompHead { text, expr } => (text.clone(), expr),
        _ => (Arc::from(""), head),
    }
}

fn contains_selector(e: &RExpr) -> bool {
    match &e.kind {
        RExprKind::CompSelector(..) => true,
        RExprKind::Unary { operand, .. } => contains_selector(operand),
        RExprKind::Binary { lhs, rhs, .. } => contains_selector(lhs) || contains_selector(rhs),
        _ => false,
    }
}

/// Whether evaluating `e` per component needs the component as a shape
/// (anything beyond selector keywords, constants, locals and operators).
fn needs_component_shape(e: &RExpr) -> bool {
    match &e.kind {
        RExprKind::Const(_) | RExprKind::Local(_) => false,
        RExprKind::CompSelector(_, args) => args.iter().any(needs_component_shape),
        RExprKind::Unary { operand, .. } => needs_component_shape(operand),
        RExprKind::Binary { lhs, rhs, .. } => {
            needs_component_shape(lhs) || needs_component_shape(rhs)
        }
        _ => true,
    }
}

/// Whether a head orients edges upwards (it names hip, valley or ridge).
fn names_upward_roof_edge(e: &RExpr) -> bool {
    match &e.kind {
        RExprKind::CompSelector(Selector::Roof(r), _) => *r != RoofEdge::Eave,
        RExprKind::Unary { operand, .. } => names_upward_roof_edge(operand),
        RExprKind::Binary { lhs, rhs, .. } => {
            names_upward_roof_edge(lhs) || names_upward_roof_edge(rhs)
        }
        _ => false,
    }
}

/// The components (not yet taken) that the head `expr` selects, ascending;
/// marks them taken.
fn select(
    cx: &mut Interp,
    frame: &[Value],
    parent: &Shape,
    comps: &mut Components,
    expr: &RExpr,
    taken: &mut [bool],
) -> Result<Vec<u32>, RtError> {
    let n = comps.len();
    let mut out = Vec::new();
    let index = |x: f64, taken: &mut [bool]| -> Vec<u32> {
        match as_index(x, n) {
            Some(k) if !taken[k] => {
                taken[k] = true;
                vec![k as u32]
            }
            _ => Vec::new(),
        }
    };
    match &expr.kind {
        RExprKind::CompSelector(sel, _) if *sel != Selector::IsTagged => {
            for (k, t) in taken.iter_mut().enumerate() {
                if !*t && comps.matches(*sel, k) {
                    *t = true;
                    out.push(k as u32);
                }
            }
            return Ok(out);
        }
        RExprKind::Const(Value::Float(x)) => return Ok(index(*x, taken)),
        _ => {}
    }
    if !contains_selector(expr) {
        // An index, or a condition without keywords: the value on the
        // current shape tells which.
        match cx.eval(expr, frame, parent)? {
            Value::Float(x) => return Ok(index(x, taken)),
            Value::Bool(_) => {}
            other => {
                return Err(RtError::new(
                    format!(
                        "a comp selector must be a selector keyword, an index (float) or a condition (bool), found {}",
                        vs::type_name(&other)
                    ),
                    expr.span,
                ))
            }
        }
    }
    let with_shape = needs_component_shape(expr);
    for (k, t) in taken.iter_mut().enumerate() {
        if *t {
            continue;
        }
        let shape;
        let on = if with_shape {
            shape = selection_shape(comps, parent, k);
            &shape
        } else {
            parent
        };
        if eval_condition(cx, frame, on, comps, k, expr)? {
            *t = true;
            out.push(k as u32);
        }
    }
    Ok(out)
}

fn as_index(x: f64, n: usize) -> Option<usize> {
    (x.is_finite() && x >= 0.0 && x < n as f64).then_some(x as usize)
}

/// Component `k` as the shape a condition is evaluated on: its geometry,
/// the current shape's pivot and scope orientation, the scope fitted.
fn selection_shape(comps: &mut Components, parent: &Shape, k: usize) -> Shape {
    let mut s = parent.clone();
    comps.fill_shape(&mut s, &[k as u32], Align::NoAlign, false, false);
    s
}

fn eval_condition(
    cx: &mut Interp,
    frame: &[Value],
    shape: &Shape,
    comps: &mut Components,
    k: usize,
    e: &RExpr,
) -> Result<bool, RtError> {
    match eval_selection(cx, frame, shape, comps, k, e)? {
        Value::Bool(b) => Ok(b),
        other => Err(RtError::new(
            format!(
                "a comp selector condition must be a bool, found {}",
                vs::type_name(&other)
            ),
            e.span,
        )),
    }
}

/// Evaluates a selection expression for component `k`: keywords are true
/// if the component matches; other parts are evaluated on `shape`.
fn eval_selection(
    cx: &mut Interp,
    frame: &[Value],
    shape: &Shape,
    comps: &mut Components,
    k: usize,
    e: &RExpr,
) -> Result<Value, RtError> {
    match &e.kind {
        RExprKind::CompSelector(sel, args) => {
            if *sel == Selector::IsTagged {
                let (query, sub) = is_tagged_args(cx, frame, shape, args, e)?;
                return Ok(Value::Bool(comps.is_tagged(k, &query, sub)));
            }
            Ok(Value::Bool(comps.matches(*sel, k)))
        }
        RExprKind::Unary {
            op,
            elementwise,
            operand,
        } if contains_selector(operand) => {
            let v = eval_selection(cx, frame, shape, comps, k, operand)?;
            vs::unary(*op, *elementwise, &v).map_err(|m| RtError::new(m, e.span))
        }
        RExprKind::Binary {
            op,
            elementwise,
            lhs,
            rhs,
        } if contains_selector(e) => {
            let a = eval_selection(cx, frame, shape, comps, k, lhs)?;
            if !elementwise {
                match (op, &a) {
                    (BinaryOp::And, Value::Bool(false)) => return Ok(Value::Bool(false)),
                    (BinaryOp::Or, Value::Bool(true)) => return Ok(Value::Bool(true)),
                    _ => {}
                }
            }
            let b = eval_selection(cx, frame, shape, comps, k, rhs)?;
            vs::binary(*op, *elementwise, &a, &b).map_err(|m| RtError::new(m, e.span))
        }
        _ => cx.eval(e, frame, shape),
    }
}

/// The arguments of `isTagged(query [, e|v])`.
fn is_tagged_args(
    cx: &mut Interp,
    frame: &[Value],
    shape: &Shape,
    args: &[RExpr],
    call: &RExpr,
) -> Result<(Arc<str>, Option<TagSub>), RtError> {
    let query = match args.first() {
        Some(q) => match cx.eval(q, frame, shape)? {
            Value::Str(s) => s,
            other => {
                return Err(RtError::new(
                    format!(
                        "the tag query of `isTagged` must be a string, found {}",
                        vs::type_name(&other)
                    ),
                    q.span,
                ))
            }
        },
        None => {
            return Err(RtError::new(
                "`isTagged` needs a tag query: isTagged(query [, e|v])",
                call.span,
            ))
        }
    };
    let sub = match args.get(1) {
        Some(sub) => {
            let a = cx.eval_arg(sub, frame, shape)?;
            Some(match selector(&a, &["e", "v"])? {
                "e" => TagSub::Edges,
                _ => TagSub::Vertices,
            })
        }
        None => None,
    };
    Ok((query, sub))
}

/// The sets of components an entry makes shapes of.
fn group(comps: &mut Components, op: BlockOp, selected: Vec<u32>) -> Vec<Vec<u32>> {
    match op {
        BlockOp::Colon => selected.into_iter().map(|k| vec![k]).collect(),
        BlockOp::Equals => vec![selected],
        BlockOp::EqualsColon => comps.connected_sets(&selected),
    }
}

// ----- the operation -----

/// Whether an operation that uses trim planes (`i()`, the primitives,
/// `trim()`) can be reached from `body`: in it, or in the rules it calls
/// at any depth. Only then do face components split with `:` get their
/// trim planes; finding them needs the mesh's topology, which was most of
/// the cost of a component split of a building's volumes, and planes no
/// operation reads change nothing.
fn uses_trim_planes(program: &crate::program::Program, body: &crate::expr::RBody) -> bool {
    fn direct(call: &OpCall) -> bool {
        use super::{CreateOp, Op};
        matches!(
            call.op,
            Op::Trim | Op::Create(CreateOp::Insert) | Op::Create(CreateOp::Primitive(_))
        )
    }
    let rules = program
        .trim_rules
        .get_or_init(|| crate::context::rules_reaching(program, &mut direct));
    let mut op_found = false;
    let mut rule_found = false;
    crate::context::Walker {
        shape_fn: &mut |_, _| {},
        op: &mut |call| op_found |= direct(call),
        rule: &mut |r| rule_found |= rules.get(r as usize).copied().unwrap_or(true),
    }
    .body(body);
    op_found || rule_found
}

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    run(cx, st, call, args, frame).map(|_| ())
}

/// [`exec`], telling for each face of the shape's mesh (in scope-local
/// coordinates, as `geometry.local()` gives it) whether an entry selected a
/// face, group or material component made of it: `modify` keeps the other
/// faces as they are. Edge, vertex and hole components mark no face.
pub(crate) fn run(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<Vec<bool>, RtError> {
    let Some(block) = &call.block else {
        return Err(RtError::new("`comp` needs a `{ ... }` block", call.span));
    };
    let kind = Kind::parse(&args[0])?;
    let align = parse_align(args.get(1))?;
    let entries = entries(block)?;
    // The shape a component split runs on is an occluder (context queries).
    cx.context_occluder(&st.shape);
    st.has_successor = true;
    let mesh = st.shape.geometry.local().clone();
    let mut comps = Components::new(mesh, kind, &st.shape, cx.initial.pivot.axes);
    let mut taken = vec![false; comps.len()];
    let last_entry = entries.len().saturating_sub(1);
    for (e, entry) in entries.into_iter().enumerate() {
        let (text, expr) = split_head(entry.head);
        let selected = select(cx, frame, &st.shape, &mut comps, expr, &mut taken)?;
        if selected.is_empty() {
            continue;
        }
        let upward = names_upward_roof_edge(expr);
        let trim = entry.op == BlockOp::Colon
            && kind == Kind::Faces
            && uses_trim_planes(cx.program, entry.body);
        let sets = group(&mut comps, entry.op, selected);
        let total = sets.len() as f64;
        // The first pass of context queries needs only the shapes on the
        // way to a label a query asks about.
        let skip = cx.context_skips_body(entry.body);
        // Without a model, face components whose rules read nothing of
        // their shape are not built: one is never empty, and nothing else
        // of its geometry shows.
        let build = kind != Kind::Faces || cx.builds_parts(entry.body);
        for (i, set) in sets.iter().enumerate() {
            // A component split that ends the shape's operations hands the
            // shape itself on to the last component of its last entry
            // (earlier entries' selections still read the shape).
            let mut child = match st.at_last && e == last_entry && i + 1 == sets.len() {
                true => cx.last_child(st, entry.head.span)?,
                false => cx.child(&st.shape, entry.head.span)?,
            };
            if skip {
                continue;
            }
            match build {
                true => comps.fill_shape(&mut child, set, align, trim, upward),
                false => child.geometry = crate::shape::Geometry::unread(),
            }
            child.comp = Some(Arc::new(CompInfo {
                sel: text.clone(),
                index: i as f64,
                total,
            }));
            let mut cst = ShapeState::new(child);
            cx.exec_body(entry.body, frame, &mut cst)?;
            cx.finish(cst);
        }
    }
    let mut used = vec![false; comps.mesh.faces.len()];
    for (k, _) in taken.iter().enumerate().filter(|(_, t)| **t) {
        if let Item::Faces { start, len } = comps.items[k] {
            for &f in &comps.face_list[start as usize..(start + len) as usize] {
                used[f as usize] = true;
            }
        }
    }
    Ok(used)
}

// ----- face-edge selection for the setback operations -----

/// The face edges of a shape (in face-edge order: every edge of every loop
/// of every face) selected by comp heads with `comp(fe)`'s semantics: the
/// edge selectors of `setback`, `setbackPerEdge` and `setbackToArea` (their
/// orientation keywords classify the edge's outward normal in the face
/// plane, as the face-edge components of `comp(fe)` are oriented). An edge
/// taken by a head is not offered to later heads. Index heads wrap around
/// (op_setback.md: "too large and negative indices are modulo wrapped").
pub(crate) struct FaceEdgeSelection {
    comps: Components,
    taken: Vec<bool>,
}

impl FaceEdgeSelection {
    pub(crate) fn new(cx: &Interp, shape: &mut Shape) -> FaceEdgeSelection {
        let mesh = shape.geometry.local().clone();
        let comps = Components::new(mesh, Kind::FaceEdges, shape, cx.initial.pivot.axes);
        let taken = vec![false; comps.len()];
        FaceEdgeSelection { comps, taken }
    }

    /// The face edges (ascending, not yet taken) the comp head `head`
    /// selects on `parent`; marks them taken.
    pub(crate) fn select(
        &mut self,
        cx: &mut Interp,
        frame: &[Value],
        parent: &Shape,
        head: &RExpr,
    ) -> Result<Vec<u32>, RtError> {
        let (_, expr) = split_head(head);
        let n = self.taken.len();
        if n > 0 && !contains_selector(expr) {
            if let Value::Float(x) = cx.eval(expr, frame, parent)? {
                if !x.is_finite() {
                    return Ok(Vec::new());
                }
                let k = (x.floor().rem_euclid(n as f64) as usize).min(n - 1);
                if self.taken[k] {
                    return Ok(Vec::new());
                }
                self.taken[k] = true;
                return Ok(vec![k as u32]);
            }
        }
        select(cx, frame, parent, &mut self.comps, expr, &mut self.taken)
    }
}

// ----- the function -----

/// The comp function: the value of each entry's expression on the
/// components it selects, in an array indexed by component (unselected
/// components get 0, "" or false).
pub fn eval_fn(
    cx: &mut Interp,
    args: &[RExpr],
    block: &RBlock<RExpr>,
    frame: &[Value],
    shape: &Shape,
    span: Span,
) -> Result<Value, RtError> {
    let mut evaluated = Vec::with_capacity(args.len());
    for a in args {
        evaluated.push(cx.eval_arg(a, frame, shape)?);
    }
    let (Some(kind_arg), true) = (evaluated.first(), evaluated.len() <= 2) else {
        return Err(RtError::new(
            "the comp function takes a component (f, e, fe, v, fv, g, m, h) and an optional alignment",
            span,
        ));
    };
    let kind = Kind::parse(kind_arg)?;
    let align = parse_align(evaluated.get(1))?;
    let entries = entries(block)?;
    let mut current = shape.clone();
    current.comp = None;
    let mesh = current.geometry.local().clone();
    let mut comps = Components::new(mesh, kind, &current, cx.initial.pivot.axes);
    let n = comps.len();
    if n > MAX_FN_COMPONENTS {
        return Err(RtError::new(
            format!(
                "the comp function's array would have {n} elements (limit {MAX_FN_COMPONENTS})"
            ),
            span,
        ));
    }
    let mut taken = vec![false; n];
    let mut values: Vec<Option<Value>> = vec![None; n];
    let mut kind_of: Option<std::mem::Discriminant<Value>> = None;
    let mut ordinal = 0u64;
    for entry in entries {
        let (text, expr) = split_head(entry.head);
        let selected = select(cx, frame, &current, &mut comps, expr, &mut taken)?;
        if selected.is_empty() {
            continue;
        }
        let upward = names_upward_roof_edge(expr);
        let sets = group(&mut comps, entry.op, selected);
        let total = sets.len() as f64;
        for (i, set) in sets.iter().enumerate() {
            let mut child = current.clone();
            child.parent_center = current.scope.center();
            child.rng.set(current.child_rng(ordinal));
            ordinal += 1;
            comps.fill_shape(&mut child, set, align, false, upward);
            child.comp = Some(Arc::new(CompInfo {
                sel: text.clone(),
                index: i as f64,
                total,
            }));
            let v = cx.eval(entry.body, frame, &child)?;
            if !matches!(v, Value::Float(_) | Value::Bool(_) | Value::Str(_)) {
                return Err(RtError::new(
                    format!(
                        "a comp function expression must be a float, string or bool, found {}",
                        vs::type_name(&v)
                    ),
                    entry.body.span,
                ));
            }
            let d = std::mem::discriminant(&v);
            match kind_of {
                None => kind_of = Some(d),
                Some(k) if k != d => {
                    return Err(RtError::new(
                        format!(
                            "all expressions of a comp function must have the same type; this one is a {}",
                            vs::type_name(&v)
                        ),
                        entry.body.span,
                    ))
                }
                _ => {}
            }
            for &k in set {
                values[k as usize] = Some(v.clone());
            }
        }
    }
    let sample = values.iter().flatten().next().cloned();
    Ok(match sample {
        Some(Value::Str(_)) => Value::StrArray(Arc::new(Array::row(
            values
                .into_iter()
                .map(|v| match v {
                    Some(Value::Str(s)) => s,
                    _ => Arc::from(""),
                })
                .collect(),
        ))),
        Some(Value::Bool(_)) => Value::BoolArray(Arc::new(Array::row(
            values
                .into_iter()
                .map(|v| matches!(v, Some(Value::Bool(true))))
                .collect(),
        ))),
        _ => Value::FloatArray(Arc::new(Array::row(
            values
                .into_iter()
                .map(|v| match v {
                    Some(Value::Float(x)) => x,
                    _ => 0.0,
                })
                .collect(),
        ))),
    })
}
