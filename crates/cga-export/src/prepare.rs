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
}

impl FacePrep {
    /// Hands every face of `mesh` worth writing to `emit`, placed in the
    /// world by `transform` (positions mapped by it, normals by its inverse
    /// transpose, and faces reversed if it mirrors, exactly as
    /// `cga_geometry::transform::transform` and `reverse_faces` would),
    /// without copying the mesh unless the map mirrors. `FaceData::material`
    /// is the face's material slot; callers map it. Faces with fewer than 3
    /// corners (edges, points) and faces of zero area are left out, and so
    /// are faces with non-finite values: their number is returned. Stops at
    /// the first error of `emit`.
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
                let n = mesh.normals.as_ref().map(|src| {
                    let nm = cga_geometry::transform::normal_matrix(t);
                    normals.clear();
                    normals.extend(src.iter().map(|&n| (nm * n).normalize_or_zero()));
                    &normals[..]
                });
                (mesh, &positions[..], n)
            }
        };
        let result = each_face(view, &mut self.triangles, emit);
        self.positions = positions;
        self.normals = normals;
        if mirrored.is_some() {
            self.mirrored = mirrored;
        }
        result
    }
}

fn each_face(
    (mesh, positions, normals): (&Mesh, &[DVec3], Option<&[DVec3]>),
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
        // normal with less work (the face is finite here).
        let normal = match loops {
            [outer] if outer.len == 4 => {
                triangulate_finite_quad(mesh, positions, *outer, triangles);
                if triangles.is_empty() {
                    continue;
                }
                quad_normal(mesh, positions, *outer)
            }
            _ => {
                let (newell, normal) = face_normals(mesh, positions, loops[0]);
                triangulate_loops_newell(mesh, positions, loops, newell, triangles);
                if triangles.is_empty() {
                    continue;
                }
                normal
            }
        };
        // No normal means zero area: nothing to see, and no valid normal
        // to write.
        let Some(normal) = normal.or_else(|| triangles_normal(mesh, positions, triangles)) else {
            continue;
        };
        emit(&FaceData {
            mesh,
            positions,
            normals,
            loops,
            material: mesh.faces[face].material,
            normal,
            triangles,
        })?;
    }
    Ok(skipped)
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
