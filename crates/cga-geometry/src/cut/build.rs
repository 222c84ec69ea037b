//! Building the output meshes of the parts from the routed faces and
//! pieces, with their attributes and tags.

use glam::{DVec2, DVec3};

use crate::mesh::{Face, Loop, Mesh};

use super::*;

impl<'m, 'b> Cutter<'m, 'b> {
    /// The parts' meshes; with `record`, also each part's plan for
    /// replaying the cut (see `replay`).
    pub(super) fn build(&mut self, mut record: Option<&mut Vec<replay::PartPlan>>) -> Vec<Mesh> {
        let mesh = self.mesh;
        let closed =
            self.only_part.is_none() && (self.bufs.planes.is_empty() || self.input_is_closed());
        self.group_items_by_part();
        let nparts = self.nplanes() + 1;
        let mut out = Vec::with_capacity(nparts);
        let mut bb = std::mem::take(&mut self.bufs.build);
        let mut cb = std::mem::take(&mut self.bufs.caps);
        bb.remap.clear();
        bb.remap.resize(self.bufs.verts.len(), NONE);
        let mut reference = None;
        for part in 0..nparts {
            if self.only_part.is_some_and(|only| only != part) {
                continue;
            }
            bb.touched.clear();
            bb.corners.clear();
            bb.loops.clear();
            bb.faces.clear();
            bb.sources.clear();
            bb.cap_normals.clear();
            let BuildBufs {
                remap,
                touched,
                corners,
                loops,
                faces,
                sources,
                cap_normals,
                ..
            } = &mut bb;
            let mut map = |v: u32| {
                let r = &mut remap[v as usize];
                if *r == NONE {
                    *r = touched.len() as u32;
                    touched.push(v);
                }
                *r
            };
            // Pieces keep their face's tags; caps get none (tag propagation
            // of cga_componentTags.md).
            let push_face = |loops: &Vec<Loop>, faces: &mut Vec<Face>, f: Face, nloops: u32| {
                faces.push(Face {
                    first_loop: loops.len() as u32 - nloops,
                    loop_count: nloops,
                    material: f.material,
                    group: f.group,
                    tags: f.tags,
                });
            };
            let items = self.part_items(part);
            for item in items {
                match *item {
                    Item::Whole(face) => {
                        let f = mesh.faces[face as usize];
                        for &l in mesh.face_loops(face as usize) {
                            let start = corners.len() as u32;
                            for c in mesh.loop_corners(l) {
                                corners.push(map(self.original_vertex(c as u32)));
                                sources.push(WCorner {
                                    v: 0,
                                    a: c as u32,
                                    b: c as u32,
                                    t: 0.0,
                                });
                            }
                            loops.push(Loop { start, len: l.len });
                        }
                        push_face(loops, faces, f, f.loop_count);
                    }
                    Item::Piece(p) => {
                        let rec = self.bufs.pieces_rec[p as usize];
                        let f = mesh.faces[rec.face as usize];
                        for li in rec.first..rec.first + rec.count {
                            let (s, n) = self.bufs.store_loops[li as usize];
                            let cs = &self.bufs.store_corners[s as usize..(s + n) as usize];
                            // The outer loop starts where its first edge runs
                            // like the source face's first edge.
                            let shift = if li == rec.first {
                                self.first_corner(cs, rec.face, &mut reference)
                            } else {
                                0
                            };
                            let start = corners.len() as u32;
                            for c in cs[shift..].iter().chain(&cs[..shift]) {
                                corners.push(map(c.v));
                                sources.push(*c);
                            }
                            loops.push(Loop { start, len: n });
                        }
                        push_face(loops, faces, f, rec.count);
                    }
                }
            }
            if closed && !items.is_empty() {
                for (plane, outward) in [
                    (part.checked_sub(1), -self.n),
                    ((part < self.nplanes()).then_some(part), self.n),
                ] {
                    let Some(plane) = plane else { continue };
                    self.caps(part, plane, outward, &mut cb);
                    for (ci, &(outer, face, _)) in cb.caps.iter().enumerate() {
                        let f = mesh.faces[face as usize];
                        let holes = (0..cb.loops.len())
                            .filter(|&l| l != outer as usize && cb.owner[l] == ci as u32);
                        let mut nloops = 0;
                        for li in std::iter::once(outer as usize).chain(holes) {
                            let (s, n, _, _) = cb.loops[li];
                            let start = corners.len() as u32;
                            for &v in &cb.loop_verts[s as usize..(s + n) as usize] {
                                corners.push(map(v));
                                sources.push(WCorner {
                                    v: cap_normals.len() as u32,
                                    a: CAP,
                                    b: CAP,
                                    t: 0.0,
                                });
                            }
                            loops.push(Loop { start, len: n });
                            nloops += 1;
                        }
                        cap_normals.push(outward);
                        push_face(loops, faces, Face { tags: 0, ..f }, nloops);
                    }
                }
            }
            let verts = &self.bufs.verts;
            let mut m = empty_like(mesh);
            m.positions = touched.iter().map(|&v| verts[v as usize]).collect();
            m.corners = corners.to_vec();
            m.loops = loops.to_vec();
            m.faces = faces.to_vec();
            for &v in touched.iter() {
                remap[v as usize] = NONE;
            }
            carry_corner_attributes(mesh, &mut m, sources, cap_normals);
            if let Some(plans) = record.as_deref_mut() {
                plans.push(replay::PartPlan {
                    positions: m.positions.clone(),
                    corners: m.corners.clone(),
                    loops: m.loops.clone(),
                    faces: m.faces.clone(),
                    sources: sources.clone(),
                    cap_normals: cap_normals.clone(),
                });
            }
            out.push(m);
        }
        self.bufs.build = bb;
        self.bufs.caps = cb;
        out
    }
}

/// The per-corner attributes of a part `m` whose corners come from
/// `sources` (see [`WCorner`]): texture coordinates and normals
/// interpolated along the original edge (caps: (0, 0) and their
/// `cap_normals`), and edge and vertex tags (`carry_corner_tags`).
pub(super) fn carry_corner_attributes(
    mesh: &Mesh,
    m: &mut Mesh,
    sources: &[WCorner],
    cap_normals: &[DVec3],
) {
    for (set, src) in mesh.uvs.iter().enumerate() {
        if let Some(uv) = src {
            let get = |i: u32| uv.get(i as usize).copied().unwrap_or(DVec2::ZERO);
            m.uvs[set] = Some(
                sources
                    .iter()
                    .map(|s| {
                        if s.a == CAP {
                            DVec2::ZERO
                        } else if s.t == 0.0 {
                            get(s.a)
                        } else {
                            get(s.a).lerp(get(s.b), s.t)
                        }
                    })
                    .collect(),
            );
        }
    }
    if let Some(nrm) = &mesh.normals {
        let get = |i: u32| nrm.get(i as usize).copied().unwrap_or(DVec3::ZERO);
        m.normals = Some(
            sources
                .iter()
                .map(|s| {
                    if s.a == CAP {
                        cap_normals[s.v as usize]
                    } else if s.t == 0.0 {
                        get(s.a)
                    } else {
                        get(s.a).lerp(get(s.b), s.t).normalize_or_zero()
                    }
                })
                .collect(),
        );
    }
    carry_corner_tags(mesh, m, sources);
}

/// Edge and vertex tags of a piece's corners from their sources: a corner
/// that is an original corner keeps its vertex tags; a corner keeps the
/// tags of the original edge its outgoing edge runs along (the edge from
/// an original corner, or through a crossing on it, to a later point of the
/// same edge); edges along the cut and cap corners get none.
pub(super) fn carry_corner_tags(mesh: &Mesh, m: &mut Mesh, sources: &[WCorner]) {
    if mesh.edge_tags.is_none() && mesh.vertex_tags.is_none() {
        return;
    }
    if mesh.vertex_tags.is_some() {
        m.vertex_tags = Some(
            sources
                .iter()
                .map(|s| {
                    if s.a != CAP && s.t == 0.0 {
                        mesh.vertex_tag_index(s.a as usize)
                    } else {
                        0
                    }
                })
                .collect(),
        );
    }
    if mesh.edge_tags.is_some() {
        // The corner after every corner in its loop of the source mesh.
        let mut next = vec![0u32; mesh.corners.len()];
        for l in &mesh.loops {
            let r = mesh.loop_corners(*l);
            for c in r.clone() {
                if let Some(x) = next.get_mut(c) {
                    *x = if c + 1 == r.end { r.start } else { c + 1 } as u32;
                }
            }
        }
        let next_of = |c: u32| next.get(c as usize).copied().unwrap_or(c);
        let mut tags = vec![0u32; sources.len()];
        for l in &m.loops {
            let r = m.loop_corners(*l);
            for i in r.clone() {
                let j = if i + 1 == r.end { r.start } else { i + 1 };
                let (si, sj) = (sources[i], sources[j]);
                if si.a == CAP || sj.a == CAP {
                    continue;
                }
                // The original edge the corner lies at the start of or on.
                let (start, end) = if si.t == 0.0 {
                    (si.a, next_of(si.a))
                } else {
                    (si.a, si.b)
                };
                let along = (sj.t > 0.0 && sj.a == start && sj.b == end && sj.t > si.t)
                    || (sj.t == 0.0 && sj.a == end);
                if along {
                    tags[i] = mesh.edge_tag_index(start as usize);
                }
            }
        }
        m.edge_tags = Some(tags);
    }
}
