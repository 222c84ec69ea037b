//! What every writer does to a mesh before it writes a face: place the
//! mesh, find each face's normal and triangles, skip faces not worth
//! writing, and map material slots to output materials.

use cga_geometry::mesh::SharedVec;
use cga_geometry::triangulate::{triangulate_finite_quad, triangulate_loops_newell};
use cga_geometry::{DAffine3, DVec3, Material, Mesh};

use crate::faces::{face_is_finite, face_normals, quad_normal};
use crate::hash::FastMap;
use crate::{ExportError, FaceData};

/// Scratch room for placing meshes and triangulating their faces, kept from
/// one mesh to the next.
#[derive(Default)]
pub(crate) struct FacePrep {
    triangles: Vec<[u32; 3]>,
    /// Placed positions and normals of the mesh being prepared.
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    /// A placed copy of a mesh whose map mirrors it (its faces reversed).
    mirrored: Option<Box<Mesh>>,
    /// The caller writes no normals: a mesh's own normals are not placed
    /// (see [`FacePrep::faces`]).
    without_normals: bool,
}

impl FacePrep {
    /// Scratch room for a caller that writes no normals.
    pub fn without_normals() -> FacePrep {
        FacePrep {
            without_normals: true,
            ..FacePrep::default()
        }
    }

    /// Hands every face of `mesh` worth writing to `emit`, placed in the
    /// world by `transform` (positions mapped by it, normals by its inverse
    /// transpose, and faces reversed if it mirrors, exactly as
    /// `cga_geometry::transform::transform` and `reverse_faces` would),
    /// without copying the mesh unless the map mirrors. `FaceData::material`
    /// is the face's material slot; callers map it. Faces with fewer than 3
    /// corners (edges, points) and faces of zero area are left out, and so
    /// are faces with non-finite values: their number is returned. Stops at
    /// the first error of `emit`. With `without_normals`, placed faces come
    /// without the mesh's own normals (the same faces and triangles).
    pub fn faces(
        &mut self,
        mesh: &Mesh,
        transform: Option<&DAffine3>,
        emit: impl FnMut(&FaceData) -> Result<(), ExportError>,
    ) -> Result<u64, ExportError> {
        let mut positions = std::mem::take(&mut self.positions);
        let mut normals = std::mem::take(&mut self.normals);
        // Taken only when a map mirrors: moving a whole `Mesh` in and out
        // for every leaf cost more than some leaves' writing.
        let mut mirrored = None;
        let view = match transform {
            None => (mesh, &mesh.positions[..], mesh.normals.as_deref()),
            Some(t) if t.matrix3.determinant() < 0.0 => {
                let m = mirrored.insert(self.mirrored.take().unwrap_or_default());
                m.copy_from(mesh);
                cga_geometry::transform::transform(m, t);
                cga_geometry::transform::reverse_faces(m);
                let m: &Mesh = m;
                (m, &m.positions[..], m.normals.as_deref())
            }
            Some(t) => {
                positions.clear();
                positions.extend(mesh.positions.iter().map(|&p| t.transform_point3(p)));
                // Placed normals are finite (`normalize_or_zero`), and a
                // face's own normals decide only its normal, never whether
                // it is written (a face left for `deferred_normal` always
                // has one): without them the same faces and triangles come
                // out.
                let own = mesh.normals.as_ref().filter(|_| !self.without_normals);
                let n = own.map(|src| {
                    let nm = cga_geometry::transform::normal_matrix(t);
                    normals.clear();
                    // Corners of a flat face repeat one normal: the same
                    // bits are placed the same (see `LastNormal`). The
                    // bits the first is compared with are a NaN, whose
                    // placed normal is zero, as it starts.
                    let mut last = ([u64::MAX; 3], DVec3::ZERO);
                    normals.extend(src.iter().map(|&n| {
                        let bits = n.to_array().map(f64::to_bits);
                        if bits != last.0 {
                            last = (bits, (nm * n).normalize_or_zero());
                        }
                        last.1
                    }));
                    &normals[..]
                });
                (mesh, &positions[..], n)
            }
        };
        let result = each_face(view, self.without_normals, &mut self.triangles, emit);
        self.positions = positions;
        self.normals = normals;
        if mirrored.is_some() {
            self.mirrored = mirrored;
        }
        result
    }
}

/// `FacePrep::faces` for a placed mesh; `without_normals`: no face normal
/// is needed but to tell which faces have none.
fn each_face(
    (mesh, positions, normals): (&Mesh, &[DVec3], Option<&[DVec3]>),
    without_normals: bool,
    triangles: &mut Vec<[u32; 3]>,
    mut emit: impl FnMut(&FaceData) -> Result<(), ExportError>,
) -> Result<u64, ExportError> {
    // Most meshes are finite throughout: then no face needs the check.
    // (Folds without stopping early, which the compiler vectorises.)
    let finite3 = |v: &[DVec3]| {
        v.iter().fold(true, |ok, p| {
            ok & p.x.is_finite() & p.y.is_finite() & p.z.is_finite()
        })
    };
    let all_finite = finite3(positions)
        && mesh.uvs[0].as_ref().is_none_or(|u| {
            u.iter()
                .fold(true, |ok, t| ok & t.x.is_finite() & t.y.is_finite())
        })
        && normals.is_none_or(finite3);
    let mut skipped = 0;
    for face in 0..mesh.faces.len() {
        // Looked up once: every step below reads them.
        let loops = mesh.face_loops(face);
        if loops[0].len < 3 {
            continue;
        }
        if !all_finite && !face_is_finite(mesh, positions, normals, face) {
            skipped += 1;
            continue;
        }
        triangles.clear();
        // Quads (most faces) take their own path: the same triangles and
        // normal with less work (the face is finite here), and the corner
        // they fan out from known without reading them back.
        let mut fan = None;
        let normal = match loops {
            [outer] if outer.len == 4 => {
                fan = triangulate_finite_quad(mesh, positions, *outer, triangles);
                if triangles.is_empty() {
                    continue;
                }
                let first_diagonal = fan == Some(0);
                // A face with normals of its own needs its face normal
                // only where one of them is zero, and one whose caller
                // writes no normals never: left for later (see
                // `deferred_normal`) where the face is sure to be written.
                let wanted_later = normals.is_some() || without_normals;
                if wanted_later && first_diagonal {
                    Deferred
                } else {
                    Known(quad_normal(mesh, positions, *outer))
                }
            }
            _ => {
                let (newell, normal) = face_normals(mesh, positions, loops[0]);
                triangulate_loops_newell(mesh, positions, loops, newell, triangles);
                if triangles.is_empty() {
                    continue;
                }
                Known(normal)
            }
        };
        // No normal means zero area: nothing to see, and no valid normal
        // to write.
        let known_normal = match normal {
            Deferred => None,
            Known(n) => match n.or_else(|| triangles_normal(mesh, positions, triangles)) {
                Some(n) => Some(n),
                None => continue,
            },
        };
        emit(&FaceData {
            mesh,
            positions,
            normals,
            loops,
            material: mesh.faces[face].material,
            known_normal,
            triangles,
            fan,
        })?;
    }
    Ok(skipped)
}

/// A face's normal as `each_face` finds it: computed (`None` for zero
/// area, unless its triangles have a normal), or left for later.
enum FaceNormal {
    Known(Option<DVec3>),
    Deferred,
}
use FaceNormal::{Deferred, Known};

/// The normal of a face `FacePrep` wrote without one (a quad with normals
/// of its own, cut along its first diagonal): what it would have given,
/// [`quad_normal`] or else the triangles' normal. The second always
/// exists for such a quad, so the face was rightly written: its two
/// triangles' cross products are those whose sum the triangulation found
/// non-zero and finite (`triangulate_finite_quad` sums them from zero in
/// the same order), and a finite non-zero vector normalises.
pub(crate) fn deferred_normal(f: &FaceData) -> DVec3 {
    let outer = f.loops[0];
    quad_normal(f.mesh, f.positions, outer)
        .or_else(|| triangles_normal(f.mesh, f.positions, f.triangles))
        .unwrap_or_default()
}

/// Area-weighted normal of triangles, for faces whose outer loop alone is
/// degenerate.
fn triangles_normal(mesh: &Mesh, positions: &[DVec3], triangles: &[[u32; 3]]) -> Option<DVec3> {
    let p = |c: u32| positions[mesh.corners[c as usize] as usize];
    let n: DVec3 = triangles
        .iter()
        .map(|&[a, b, c]| (p(b) - p(a)).cross(p(c) - p(a)))
        .sum();
    n.try_normalize()
}

/// Output material ids of the material slots of the mesh being written,
/// found when a face first uses a slot.
#[derive(Default)]
pub(crate) struct SlotIds {
    /// Per slot of the current material list (`UNSEEN` until a face uses it).
    ids: Vec<u32>,
    /// The slot ids of material lists seen before, by the address of the
    /// shared list (the entry holds a clone, so the address stays valid):
    /// the many shapes that share a material list are looked up once, not
    /// compared by value slot by slot.
    known: FastMap<usize, (SharedVec<Material>, Vec<u32>)>,
}

const UNSEEN: u32 = u32::MAX;

/// Entries of [`SlotIds::known`] above which it is emptied, so memory stays
/// bounded on cities of distinct materials.
const KNOWN_LIMIT: usize = 1 << 12;

impl SlotIds {
    /// Starts a mesh whose slots hold `materials`.
    pub fn begin(&mut self, materials: &SharedVec<Material>) {
        let key = materials.as_ptr() as usize;
        match self.known.get_mut(&key) {
            Some((_, ids)) => std::mem::swap(&mut self.ids, ids),
            None => {
                self.ids.clear();
                self.ids.resize(materials.len(), UNSEEN);
            }
        }
    }

    /// The output id of `slot`, from `intern` the first time.
    #[inline]
    pub fn id(&mut self, slot: u32, intern: impl FnOnce() -> u32) -> u32 {
        let id = &mut self.ids[slot as usize];
        if *id == UNSEEN {
            *id = intern();
        }
        *id
    }

    /// Ends the mesh begun with the same `materials`, remembering its slot
    /// ids for the next mesh that shares the list.
    pub fn end(&mut self, materials: &SharedVec<Material>) {
        let key = materials.as_ptr() as usize;
        match self.known.get_mut(&key) {
            Some((_, ids)) => std::mem::swap(&mut self.ids, ids),
            None => {
                if self.known.len() >= KNOWN_LIMIT {
                    self.known.clear();
                }
                self.known
                    .insert(key, (materials.clone(), self.ids.clone()));
            }
        }
    }

    /// Forgets every id (the ids they map to start again).
    pub fn clear(&mut self) {
        self.known.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::faces::face_normals;
    use cga_geometry::primitive::cube;

    /// The normal each face is written with, and whether it was left for
    /// later, for a cube whose corners carry normals (one of them zero).
    fn written_normals(transform: Option<&DAffine3>) -> Vec<(Option<DVec3>, DVec3, DVec3)> {
        let mut mesh = cube(DVec3::new(2.0, 3.0, 4.0));
        let mut normals: Vec<DVec3> = (0..mesh.corners.len())
            .map(|c| DVec3::new(0.1, 0.2, 1.0 + c as f64))
            .collect();
        normals[5] = DVec3::ZERO;
        mesh.normals = Some(normals);
        let mut prep = FacePrep::default();
        let mut out = Vec::new();
        let skipped = prep
            .faces(&mesh, transform, |f| {
                let (_, reference) = face_normals(f.mesh, f.positions, f.loops[0]);
                out.push((
                    f.known_normal,
                    f.normal(),
                    reference.expect("a face of a cube has area"),
                ));
                Ok(())
            })
            .expect("no writer error");
        assert_eq!(skipped, 0);
        out
    }

    #[test]
    fn a_quad_with_normals_of_its_own_gets_its_face_normal_when_asked() {
        let turned =
            DAffine3::from_rotation_y(0.3) * DAffine3::from_translation(DVec3::new(5.0, 1.0, -2.0));
        for transform in [None, Some(&turned)] {
            let faces = written_normals(transform);
            assert_eq!(faces.len(), 6, "every face of the cube is written");
            for (known, normal, reference) in faces {
                // Convex quads are cut along their first diagonal: their
                // normal is left for later, and is the one computed then.
                assert_eq!(known, None);
                assert_eq!(normal, reference);
                assert!((normal.length() - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn a_face_without_normals_of_its_own_has_its_normal_computed() {
        let mut mesh = cube(DVec3::ONE);
        mesh.normals = None;
        let mut prep = FacePrep::default();
        let mut known = Vec::new();
        prep.faces(&mesh, None, |f| {
            known.push(f.known_normal);
            Ok(())
        })
        .expect("no writer error");
        assert_eq!(known.len(), 6);
        assert!(known
            .iter()
            .all(|n| n.is_some_and(|n| (n.length() - 1.0).abs() < 1e-12)));
    }
}
