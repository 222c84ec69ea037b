//! Reading an asset file by its format ([`load_asset`]), and what the
//! readers other than OBJ share: the scene-graph transform of an instance,
//! the conversion of a file's units and up axis to CGA's (metres, y up),
//! and a builder that turns indexed polygons into a [`Mesh`] in file order.

use std::path::Path;

use glam::{DAffine3, DMat3, DVec2, DVec3};

use crate::material::Material;
use crate::mesh::Mesh;
use crate::obj::ObjAsset;

/// Reads a file's bytes (the asset and the files it names: OBJ material
/// libraries, glTF buffers); the error is a message.
pub type ReadFile<'a> = dyn Fn(&Path) -> Result<Vec<u8>, String> + 'a;

/// Reads the asset file `path` by its extension, through `read`: OBJ,
/// COLLADA (`.dae`), glTF (`.gltf`, `.glb`). The other formats the `i()`
/// page lists (FBX, USD, DWG, IFC) have no well-kept pure-Rust reader: they
/// are an error naming the file and the format, as is an unknown extension
/// or an asset without polygons. The error is a message for a warning; the
/// model goes on without the asset.
pub fn load_asset(path: &Path, read: &ReadFile) -> Result<ObjAsset, String> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let shown = path.display();
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let format = match ext.as_str() {
        "obj" | "dae" | "gltf" | "glb" => None,
        "fbx" => Some("FBX"),
        "dwg" => Some("DWG"),
        "ifc" => Some("IFC"),
        "usd" | "usda" | "usdc" | "usdz" => Some("USD"),
        _ => {
            return Err(format!(
            "cannot load asset {shown}: unknown asset format (expected .obj, .dae, .gltf or .glb)"
        ))
        }
    };
    if let Some(format) = format {
        return Err(format!(
            "cannot load asset {shown}: {format} assets are not read by this engine (no well-kept pure-Rust reader); convert it to glTF, COLLADA or OBJ"
        ));
    }
    let bytes = read(path).map_err(|e| format!("cannot load asset {shown}: {e}"))?;
    let asset = match ext.as_str() {
        "obj" => {
            let text = String::from_utf8_lossy(&bytes);
            crate::obj::parse_obj(&text, &dir, |name| {
                read(&dir.join(name))
                    .map(|b| String::from_utf8_lossy(&b).into_owned())
                    .map_err(|e| format!("cannot read material library: {e}"))
            })
        }
        "dae" => crate::collada::parse_collada(&String::from_utf8_lossy(&bytes), &dir),
        _ => crate::gltf_asset::parse_gltf(&bytes, &dir, read),
    }
    .map_err(|e| format!("cannot load asset {shown}: {e}"))?;
    if asset.mesh.faces.is_empty() {
        return Err(format!("asset {shown} has no polygons"));
    }
    Ok(asset)
}

/// Decodes `%XX` escapes of a URI path (`my%20file.png`).
pub(crate) fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let Some(b) = s
                .get(i + 1..i + 3)
                .and_then(|h| u8::from_str_radix(h, 16).ok())
            {
                out.push(b);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Polygons added in order; positions are shared within one instance of a
/// geometry (so that faces stay connected for `comp`), texture coordinates
/// and normals are per corner.
pub(crate) struct MeshBuilder {
    mesh: Mesh,
    uvs: Vec<DVec2>,
    normals: Vec<DVec3>,
    has_uvs: bool,
    has_normals: bool,
}

impl MeshBuilder {
    pub fn new() -> MeshBuilder {
        let mut mesh = Mesh::new();
        mesh.materials.clear();
        mesh.groups.clear();
        MeshBuilder {
            mesh,
            uvs: Vec::new(),
            normals: Vec::new(),
            has_uvs: false,
            has_normals: false,
        }
    }

    /// Adds a material slot.
    pub fn material(&mut self, m: Material) -> u32 {
        self.mesh.materials.push(m);
        self.mesh.materials.len() as u32 - 1
    }

    /// The group named `name` (a node's name), added on first use.
    pub fn group(&mut self, name: &str) -> u32 {
        match self.mesh.groups.iter().position(|g| g == name) {
            Some(i) => i as u32,
            None => {
                self.mesh.groups.push(name.to_string());
                self.mesh.groups.len() as u32 - 1
            }
        }
    }

    /// Adds positions (already transformed); returns the index of the first.
    pub fn positions(&mut self, pts: impl IntoIterator<Item = DVec3>) -> u32 {
        let base = self.mesh.positions.len() as u32;
        self.mesh.positions.extend(pts);
        base
    }

    /// Adds a polygon of mesh position indices with optional per-corner
    /// texture coordinates (UV set 0) and normals. A polygon with fewer than
    /// three distinct corners is dropped (returns false).
    pub fn polygon(
        &mut self,
        idx: &[u32],
        uvs: Option<&[DVec2]>,
        normals: Option<&[DVec3]>,
        material: u32,
        group: u32,
    ) -> bool {
        let mut distinct = idx.to_vec();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < 3 || idx.iter().any(|&i| i as usize >= self.mesh.positions.len()) {
            return false;
        }
        let f = self.mesh.add_face(&[idx], material);
        self.mesh.faces[f].group = group;
        for k in 0..idx.len() {
            match uvs.and_then(|u| u.get(k)) {
                Some(&uv) => {
                    self.has_uvs = true;
                    self.uvs.push(uv);
                }
                None => self.uvs.push(DVec2::ZERO),
            }
            match normals.and_then(|n| n.get(k)) {
                Some(&n) => {
                    self.has_normals = true;
                    self.normals.push(n);
                }
                None => self.normals.push(DVec3::ZERO),
            }
        }
        true
    }

    pub fn finish(mut self) -> Mesh {
        if self.mesh.materials.is_empty() {
            self.mesh.materials.push(Material::default());
        }
        if self.mesh.groups.is_empty() {
            self.mesh.groups.push(String::new());
        }
        if self.has_uvs {
            self.mesh.uvs[0] = Some(self.uvs);
        }
        if self.has_normals {
            self.mesh.normals = Some(self.normals);
        }
        self.mesh
    }
}

/// An instance transform: points by `affine`, normals by the inverse
/// transpose; a mirroring transform reverses the winding.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Placement {
    pub affine: DAffine3,
}

impl Placement {
    pub fn new(affine: DAffine3) -> Placement {
        Placement { affine }
    }

    pub fn point(&self, p: DVec3) -> DVec3 {
        self.affine.transform_point3(p)
    }

    pub fn normal(&self, n: DVec3) -> DVec3 {
        let m: DMat3 = self.affine.matrix3;
        let inv_t = if m.determinant().abs() > 1e-300 {
            m.inverse().transpose()
        } else {
            m
        };
        (inv_t * n).normalize_or_zero()
    }

    /// Whether the transform mirrors (faces must be reversed to keep their
    /// normals pointing outwards).
    pub fn mirrors(&self) -> bool {
        self.affine.matrix3.determinant() < 0.0
    }
}

/// The rotation taking a file's up axis to CGA's +y (x stays right-handed):
/// `Z_UP` maps (x, y, z) to (x, z, -y); `X_UP` maps (x, y, z) to (-y, x, z).
pub(crate) fn up_axis_to_y(axis: char) -> DMat3 {
    match axis {
        'Z' => DMat3::from_cols(DVec3::X, -DVec3::Z, DVec3::Y),
        'X' => DMat3::from_cols(DVec3::Y, -DVec3::X, DVec3::Z),
        _ => DMat3::IDENTITY,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Files are read through the given reader (a world of the caller's:
    /// memory here), the asset and what it names.
    #[test]
    fn assets_are_read_through_the_reader() {
        let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nusemtl red\nf 1 2 3\n";
        let mtl = "newmtl red\nKd 1 0 0\n";
        let files: Vec<(&str, &str)> = vec![("mem/a.obj", obj), ("mem/m.mtl", mtl)];
        let read = |p: &Path| -> Result<Vec<u8>, String> {
            files
                .iter()
                .find(|(n, _)| Path::new(n) == p)
                .map(|(_, t)| t.as_bytes().to_vec())
                .ok_or_else(|| format!("no {}", p.display()))
        };
        let a = load_asset(Path::new("mem/a.obj"), &read).unwrap();
        assert_eq!(a.mesh.faces.len(), 1);
        assert_eq!(
            a.mesh.materials[a.mesh.faces[0].material as usize].color,
            [1.0, 0.0, 0.0]
        );
        let e = load_asset(Path::new("mem/b.dae"), &read).unwrap_err();
        assert!(e.contains("mem/b.dae") && e.contains("no mem/b.dae"), "{e}");
        let e = load_asset(Path::new("mem/a.FBX"), &read).unwrap_err();
        assert!(e.contains("FBX assets are not read"), "{e}");
    }

    #[test]
    fn up_axes() {
        let z = up_axis_to_y('Z');
        assert_eq!(z * DVec3::new(1.0, 2.0, 3.0), DVec3::new(1.0, 3.0, -2.0));
        assert!((z.determinant() - 1.0).abs() < 1e-12);
        let x = up_axis_to_y('X');
        assert_eq!(x * DVec3::new(1.0, 2.0, 3.0), DVec3::new(-2.0, 1.0, 3.0));
        assert!((x.determinant() - 1.0).abs() < 1e-12);
    }
}
