//! Roof edge classes (`eave`, `hip`, `valley`, `ridge`) of any mesh, from
//! its geometry alone: what `comp(e)`'s roof selectors read.
//!
//! [`crate::roof`] knows the role of every face it builds; a mesh that has
//! been transformed, split into faces and re-assembled, or loaded from an
//! asset does not. Here a face's role is read from its normal against the
//! up direction: facing up (even slightly) it is a *roof face*, facing down
//! a *base*, otherwise (vertical) a wall or pediment. With these roles the
//! rules are those of [`crate::roof`], so that both agree on every roof it
//! builds:
//!
//! - *eave*: an edge of exactly one roof face whose other faces (if any) are
//!   bases, with both ends at the lowest level of that roof face (so it is
//!   horizontal; within half a degree, for assets that are not exact). It runs as the roof face runs: counter-clockwise around
//!   the footprint seen from above.
//! - between exactly two roof faces: *valley* if they form a concavity,
//!   else *hip* if it touches an eave, else *ridge*.
//! - every other edge (bases, walls, rakes along pediments) has no class.

use glam::DVec3;

use crate::mesh::Mesh;
use crate::roof::RoofEdgeKind;
use crate::topology::{mesh_tolerance, EdgeUse, Topology};

/// Normals whose component along "up" is above this count as facing up
/// (below its negative: facing down). About 0.06 degrees: a roof plane is
/// never that flat, a wall never that far off vertical.
const FACING: f64 = 1e-3;

/// Roof classes of the edges of a mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RoofEdges {
    /// Class of every edge of the topology, in its order.
    pub kinds: Vec<RoofEdgeKind>,
    /// For eaves, the use by the roof face (its direction is the eave's).
    pub eave_use: Vec<Option<EdgeUse>>,
}

/// Classifies the edges of `topo` (the topology of `mesh`); `normals` are
/// the unit face normals (zero for faces without area) and `up` the unit up
/// direction, all in the mesh's coordinates.
pub fn classify_roof_edges(
    mesh: &Mesh,
    topo: &Topology,
    normals: &[DVec3],
    up: DVec3,
) -> RoofEdges {
    #[derive(Clone, Copy, PartialEq, Eq)]
    enum Role {
        Roof,
        Base,
        Other,
    }
    let role: Vec<Role> = normals
        .iter()
        .map(|n| {
            let d = n.dot(up);
            if d > FACING {
                Role::Roof
            } else if d < -FACING {
                Role::Base
            } else {
                Role::Other
            }
        })
        .collect();
    let height = |p: u32| mesh.positions[p as usize].dot(up);
    let tol = mesh_tolerance(mesh) * 100.0;
    // Lowest level of every roof face.
    let mut low = vec![f64::INFINITY; mesh.faces.len()];
    for (f, lo) in low.iter_mut().enumerate() {
        if role[f] != Role::Roof {
            continue;
        }
        for &l in mesh.face_loops(f) {
            for &p in mesh.loop_indices(l) {
                *lo = lo.min(height(p));
            }
        }
    }
    let ne = topo.edges.len();
    let mut kinds = vec![RoofEdgeKind::Other; ne];
    let mut eave_use = vec![None; ne];
    let mut eave_vertex = vec![false; topo.weld.count];
    for e in 0..ne {
        let uses = topo.edge_uses(e);
        let mut roof_use = None;
        let mut roofs = 0;
        let mut others_ok = true;
        let mut last_face = u32::MAX;
        for u in uses {
            if u.face == last_face {
                continue;
            }
            last_face = u.face;
            match role[u.face as usize] {
                Role::Roof => {
                    roofs += 1;
                    roof_use = Some(*u);
                }
                Role::Base => {}
                Role::Other => others_ok = false,
            }
        }
        if roofs != 1 || !others_ok {
            continue;
        }
        let u = roof_use.expect("one roof use");
        let f = u.face as usize;
        let [a, b] = topo.edges[e].p;
        // At the lowest level, horizontal within half a degree (assets are
        // not always exact).
        let len = (mesh.positions[b as usize] - mesh.positions[a as usize]).length();
        let slack = tol + len * 0.5f64.to_radians().sin();
        if (height(a) - low[f]).abs() <= slack && (height(b) - low[f]).abs() <= slack {
            kinds[e] = RoofEdgeKind::Eave;
            eave_use[e] = Some(u);
            let [va, vb] = topo.edges[e].v;
            eave_vertex[va as usize] = true;
            eave_vertex[vb as usize] = true;
        }
    }
    for (e, kind) in kinds.iter_mut().enumerate() {
        let uses = topo.edge_uses(e);
        if uses.len() != 2
            || uses[0].face == uses[1].face
            || role[uses[0].face as usize] != Role::Roof
            || role[uses[1].face as usize] != Role::Roof
        {
            continue;
        }
        let (f1, f2) = (uses[0].face as usize, uses[1].face as usize);
        let [a, b] = topo.edges[e].p;
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        let n1 = normals[f1];
        // The point of f2 farthest from the edge tells the dihedral's sense:
        // above f1's plane means the two faces form a concavity.
        let dir = (pb - pa).normalize_or_zero();
        let mut best = (0.0, 0.0);
        for &l in mesh.face_loops(f2) {
            for q in mesh.loop_points(l) {
                let r = q - pa;
                let off = (r - dir * r.dot(dir)).length();
                if off > best.0 {
                    best = (off, r.dot(n1));
                }
            }
        }
        let [va, vb] = topo.edges[e].v;
        *kind = if best.1 > tol {
            RoofEdgeKind::Valley
        } else if eave_vertex[va as usize] || eave_vertex[vb as usize] {
            RoofEdgeKind::Hip
        } else {
            RoofEdgeKind::Ridge
        };
    }
    RoofEdges { kinds, eave_use }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::face_normal;
    use crate::roof::{roof, RoofKind, RoofSlope};

    fn footprint(pts: &[(f64, f64)]) -> Mesh {
        let p: Vec<DVec3> = pts.iter().map(|&(x, z)| DVec3::new(x, 0.0, z)).collect();
        Mesh::polygon(&p)
    }

    /// The classes read from the geometry are the ones the roof builder
    /// gives, on hip, gable, pyramid, shed, L-shaped and concave roofs,
    /// with and without overhangs.
    #[test]
    fn agrees_with_the_roof_builder() {
        let rect = footprint(&[(0.0, 0.0), (10.0, 0.0), (10.0, -6.0), (0.0, -6.0)]);
        let l = footprint(&[
            (0.0, 0.0),
            (12.0, 0.0),
            (12.0, -5.0),
            (5.0, -5.0),
            (5.0, -12.0),
            (0.0, -12.0),
        ]);
        let u = footprint(&[
            (0.0, 0.0),
            (15.0, 0.0),
            (15.0, -12.0),
            (10.0, -12.0),
            (10.0, -5.0),
            (5.0, -5.0),
            (5.0, -12.0),
            (0.0, -12.0),
        ]);
        let pentagon = footprint(&[
            (0.0, 0.0),
            (8.0, 0.0),
            (10.0, -6.0),
            (4.0, -10.0),
            (-2.0, -6.0),
        ]);
        let hip = |o| RoofKind::Hip {
            overhang: o,
            even: false,
        };
        let gable = |o| RoofKind::Gable {
            overhang_x: o,
            overhang_y: o,
            even: false,
            index: None,
        };
        let cases = [
            (&rect, hip(0.0)),
            (&rect, hip(1.0)),
            (&rect, gable(0.0)),
            (&rect, gable(0.5)),
            (&l, hip(0.0)),
            (&l, gable(0.0)),
            (&u, hip(0.0)),
            (&u, gable(0.0)),
            (&pentagon, RoofKind::Pyramid),
            (&pentagon, hip(0.0)),
            (&l, RoofKind::Shed { index: 1 }),
        ];
        for (k, (m, kind)) in cases.into_iter().enumerate() {
            let r = roof(m, RoofSlope::Angle(30.0), kind);
            assert!(r.failed.is_empty(), "case {k}");
            let topo = Topology::new(&r.mesh);
            let normals: Vec<DVec3> = (0..r.mesh.faces.len())
                .map(|f| face_normal(&r.mesh, f))
                .collect();
            let c = classify_roof_edges(&r.mesh, &topo, &normals, DVec3::Y);
            assert_eq!(c.kinds, r.edge_kinds, "case {k}: {kind:?}");
            for (e, u) in c.eave_use.iter().enumerate() {
                if let Some(u) = u {
                    let c0 = u.corner as usize;
                    let l = r
                        .mesh
                        .face_loops(u.face as usize)
                        .iter()
                        .copied()
                        .find(|l| r.mesh.loop_corners(*l).contains(&c0))
                        .unwrap();
                    let next = if c0 + 1 == r.mesh.loop_corners(l).end {
                        l.start as usize
                    } else {
                        c0 + 1
                    };
                    assert_eq!(
                        [r.mesh.corners[c0], r.mesh.corners[next]],
                        r.edge_ends[e],
                        "case {k}: eave {e} direction"
                    );
                }
            }
        }
    }

    #[test]
    fn counts_on_known_roofs() {
        let count = |c: &RoofEdges, k| c.kinds.iter().filter(|&&x| x == k).count();
        let l = footprint(&[
            (0.0, 0.0),
            (12.0, 0.0),
            (12.0, -5.0),
            (5.0, -5.0),
            (5.0, -12.0),
            (0.0, -12.0),
        ]);
        let r = roof(
            &l,
            RoofSlope::Angle(30.0),
            RoofKind::Hip {
                overhang: 0.0,
                even: false,
            },
        );
        let topo = Topology::new(&r.mesh);
        let normals: Vec<DVec3> = (0..r.mesh.faces.len())
            .map(|f| face_normal(&r.mesh, f))
            .collect();
        let c = classify_roof_edges(&r.mesh, &topo, &normals, DVec3::Y);
        // Six eaves, one valley at the inner corner, four hips at the outer
        // corners of the wings... and the ridges between.
        assert_eq!(count(&c, RoofEdgeKind::Eave), 6);
        assert_eq!(count(&c, RoofEdgeKind::Valley), 1);
        assert_eq!(count(&c, RoofEdgeKind::Hip), 5);
        assert_eq!(count(&c, RoofEdgeKind::Ridge), 2);
    }
}
