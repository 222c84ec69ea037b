//! Loading COLLADA (`.dae`) assets into a [`Mesh`], as CGA's `i()` reads
//! them (op_i.md: "The COLLADA reader imports the full scene graph
//! including transformation nodes. Extra tags are ignored").
//!
//! What is read: the `<asset>`'s `unit` (scaled to metres) and `up_axis`
//! (turned to CGA's +y); the visual scene the `<scene>` names (else the
//! first), its nodes with their `matrix`, `translate`, `rotate` and `scale`
//! transforms in document order, `instance_geometry` (with its material
//! bindings) and `instance_node`; geometry `<mesh>`es with `triangles`,
//! `polylist`, `polygons` (holes dropped), `trifans` and `tristrips`, their
//! positions, normals and first texture coordinate set; materials through
//! their effect's `diffuse` colour or texture (the image file, relative to
//! the `.dae`). A file without a visual scene inserts every geometry once,
//! untransformed. Each node's polygons are a group named after the node.
//!
//! Errors are values: malformed XML, or numbers that do not parse, name
//! the line; what cannot be used (lines, missing sources, unknown
//! elements) is skipped, with a warning where it loses geometry.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{DAffine3, DMat3, DMat4, DVec2, DVec3};
use roxmltree::{Document, Node};

use crate::asset_mesh::{percent_decode, up_axis_to_y, MeshBuilder, Placement};
use crate::material::Material;
use crate::obj::{ObjAsset, ObjError};

/// Nesting of `instance_node` references followed at most (a file that
/// instances a node inside itself must not recurse without end).
const MAX_DEPTH: usize = 64;

/// Loads a `.dae` file; texture paths are joined to its folder.
pub fn load_collada(path: &Path) -> Result<ObjAsset, ObjError> {
    let bytes = std::fs::read(path).map_err(|e| ObjError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    parse_collada(&String::from_utf8_lossy(&bytes), &dir)
}

/// Parses COLLADA text; `dir` is the folder image paths are relative to.
pub fn parse_collada(text: &str, dir: &Path) -> Result<ObjAsset, ObjError> {
    let doc = Document::parse(text).map_err(|e| ObjError::Parse {
        line: e.pos().row as usize,
        message: format!("not a COLLADA document: {e}"),
    })?;
    let root = doc.root_element();
    if root.tag_name().name() != "COLLADA" {
        return Err(ObjError::Parse {
            line: line_of(&doc, root),
            message: format!(
                "not a COLLADA document (root element <{}>)",
                root.tag_name().name()
            ),
        });
    }
    let mut r = Reader {
        doc: &doc,
        dir,
        ids: doc
            .descendants()
            .filter_map(|n| n.attribute("id").map(|id| (id, n)))
            .collect(),
        b: MeshBuilder::new(),
        materials: HashMap::new(),
        warnings: Vec::new(),
    };
    let asset = child(root, "asset");
    let meter = asset
        .and_then(|a| child(a, "unit"))
        .and_then(|u| u.attribute("meter"))
        .and_then(|m| m.trim().parse::<f64>().ok())
        .filter(|m| m.is_finite() && *m > 0.0)
        .unwrap_or(1.0);
    let up = asset
        .and_then(|a| child(a, "up_axis"))
        .and_then(|u| u.text())
        .and_then(|t| t.trim().chars().next())
        .unwrap_or('Y');
    let base = DAffine3::from_mat3(up_axis_to_y(up) * DMat3::from_diagonal(DVec3::splat(meter)));

    let scene = child(root, "scene")
        .and_then(|s| child(s, "instance_visual_scene"))
        .and_then(|i| r.target(i, "url"))
        .or_else(|| {
            child(root, "library_visual_scenes").and_then(|l| children(l, "visual_scene").next())
        });
    match scene {
        Some(vs) => {
            for node in children(vs, "node") {
                r.node(node, base, 0)?;
            }
        }
        None => {
            let geometries: Vec<Node> = children(root, "library_geometries")
                .flat_map(|l| children(l, "geometry"))
                .collect();
            for g in geometries {
                let name = g.attribute("name").or(g.attribute("id")).unwrap_or("");
                r.geometry(g, base, &HashMap::new(), name)?;
            }
        }
    }
    Ok(ObjAsset {
        mesh: r.b.finish(),
        warnings: r.warnings,
    })
}

struct Reader<'a, 'input> {
    doc: &'a Document<'input>,
    dir: &'a Path,
    ids: HashMap<&'a str, Node<'a, 'input>>,
    b: MeshBuilder,
    /// Material slots by COLLADA material id ("" for unbound polygons).
    materials: HashMap<String, u32>,
    warnings: Vec<String>,
}

impl<'a, 'input> Reader<'a, 'input> {
    /// The element a `#id` reference in attribute `attr` points to.
    fn target(&self, n: Node<'a, 'input>, attr: &str) -> Option<Node<'a, 'input>> {
        let url = n.attribute(attr)?;
        self.ids.get(url.trim().trim_start_matches('#')).copied()
    }

    fn node(
        &mut self,
        n: Node<'a, 'input>,
        parent: DAffine3,
        depth: usize,
    ) -> Result<(), ObjError> {
        if depth > MAX_DEPTH {
            self.warnings.push(format!(
                "line {}: node instances nested deeper than {MAX_DEPTH}; the rest is skipped",
                line_of(self.doc, n)
            ));
            return Ok(());
        }
        let mut xf = parent;
        for t in n.children().filter(Node::is_element) {
            let local = match t.tag_name().name() {
                "matrix" => {
                    let v = self.floats(t)?;
                    if v.len() < 16 {
                        continue;
                    }
                    // Row-major in the file.
                    let m = DMat4::from_cols_array(&[
                        v[0], v[4], v[8], v[12], v[1], v[5], v[9], v[13], v[2], v[6], v[10], v[14],
                        v[3], v[7], v[11], v[15],
                    ]);
                    DAffine3::from_mat4(m)
                }
                "translate" => match self.floats(t)?[..] {
                    [x, y, z, ..] => DAffine3::from_translation(DVec3::new(x, y, z)),
                    _ => continue,
                },
                "scale" => match self.floats(t)?[..] {
                    [x, y, z, ..] => DAffine3::from_scale(DVec3::new(x, y, z)),
                    _ => continue,
                },
                "rotate" => match self.floats(t)?[..] {
                    [x, y, z, deg, ..] => {
                        let axis = DVec3::new(x, y, z).normalize_or_zero();
                        if axis == DVec3::ZERO {
                            continue;
                        }
                        DAffine3::from_axis_angle(axis, deg.to_radians())
                    }
                    _ => continue,
                },
                _ => continue,
            };
            xf *= local;
        }
        let name = n.attribute("name").or(n.attribute("id")).unwrap_or("");
        for c in n.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "instance_geometry" => {
                    let Some(g) = self.target(c, "url") else {
                        self.warnings.push(format!(
                            "line {}: instance_geometry names no geometry of the file",
                            line_of(self.doc, c)
                        ));
                        continue;
                    };
                    let bindings = bindings(c);
                    self.geometry(g, xf, &bindings, name)?;
                }
                "instance_node" => {
                    if let Some(t) = self.target(c, "url") {
                        self.node(t, xf, depth + 1)?;
                    }
                }
                "node" => self.node(c, xf, depth + 1)?,
                _ => {}
            }
        }
        Ok(())
    }

    fn floats(&self, n: Node) -> Result<Vec<f64>, ObjError> {
        numbers(n.text().unwrap_or("")).map_err(|t| ObjError::Parse {
            line: line_of(self.doc, n),
            message: format!("`{t}` is not a number"),
        })
    }

    fn ints(&self, n: Node) -> Result<Vec<usize>, ObjError> {
        n.text()
            .unwrap_or("")
            .split_ascii_whitespace()
            .map(|t| {
                t.parse::<usize>().map_err(|_| ObjError::Parse {
                    line: line_of(self.doc, n),
                    message: format!("`{t}` is not an index"),
                })
            })
            .collect()
    }

    /// The values of a `<source>` as tuples of its accessor's stride.
    fn source(&self, s: Node) -> Result<(Vec<f64>, usize), ObjError> {
        let values = match child(s, "float_array") {
            Some(a) => self.floats(a)?,
            None => Vec::new(),
        };
        let stride = child(s, "technique_common")
            .and_then(|t| child(t, "accessor"))
            .and_then(|a| a.attribute("stride"))
            .and_then(|v| v.parse::<usize>().ok())
            .filter(|&s| s > 0)
            .unwrap_or(1);
        Ok((values, stride))
    }

    fn geometry(
        &mut self,
        g: Node<'a, 'input>,
        xf: DAffine3,
        bindings: &HashMap<String, String>,
        group: &str,
    ) -> Result<(), ObjError> {
        let Some(mesh) = child(g, "mesh") else {
            return Ok(()); // splines, convex meshes, brep: not polygons
        };
        let place = Placement::new(xf);
        let group = self.b.group(group);
        // <vertices>: its POSITION source (and per-vertex normals/uvs).
        let Some(vertices) = child(mesh, "vertices") else {
            self.warnings.push(format!(
                "line {}: a mesh without <vertices> is skipped",
                line_of(self.doc, mesh)
            ));
            return Ok(());
        };
        let vertex_input =
            |sem: &str| children(vertices, "input").find(|i| i.attribute("semantic") == Some(sem));
        let Some(pos_src) = vertex_input("POSITION").and_then(|i| self.target(i, "source")) else {
            return Ok(());
        };
        let (pos, pstride) = self.source(pos_src)?;
        if pstride < 3 {
            return Ok(());
        }
        let base = self.b.positions(
            pos.chunks_exact(pstride)
                .map(|c| place.point(DVec3::new(c[0], c[1], c[2]))),
        );
        let n_pos = pos.len() / pstride;
        // Per-vertex normals and uvs given inside <vertices>.
        let v_normals = match vertex_input("NORMAL").and_then(|i| self.target(i, "source")) {
            Some(s) => Some(self.source(s)?),
            None => None,
        };
        let v_uvs = match vertex_input("TEXCOORD").and_then(|i| self.target(i, "source")) {
            Some(s) => Some(self.source(s)?),
            None => None,
        };
        for prim in mesh.children().filter(Node::is_element) {
            let kind = prim.tag_name().name();
            if !matches!(
                kind,
                "triangles" | "polylist" | "polygons" | "trifans" | "tristrips"
            ) {
                continue;
            }
            let inputs: Vec<Node> = children(prim, "input").collect();
            let stride = inputs
                .iter()
                .filter_map(|i| i.attribute("offset")?.parse::<usize>().ok())
                .max()
                .map_or(1, |m| m + 1);
            let offset_of = |sem: &str| {
                inputs
                    .iter()
                    .filter(|i| i.attribute("semantic") == Some(sem))
                    .min_by_key(|i| {
                        i.attribute("set")
                            .and_then(|s| s.parse::<u32>().ok())
                            .unwrap_or(0)
                    })
                    .map(|i| {
                        (
                            i.attribute("offset")
                                .and_then(|o| o.parse::<usize>().ok())
                                .unwrap_or(0),
                            *i,
                        )
                    })
            };
            let Some((v_off, _)) = offset_of("VERTEX") else {
                continue;
            };
            let normals = match offset_of("NORMAL") {
                Some((o, i)) => match self.target(i, "source") {
                    Some(s) => Some((o, self.source(s)?)),
                    None => None,
                },
                None => None,
            };
            let uvs = match offset_of("TEXCOORD") {
                Some((o, i)) => match self.target(i, "source") {
                    Some(s) => Some((o, self.source(s)?)),
                    None => None,
                },
                None => None,
            };
            let material = self.material_slot(prim.attribute("material"), bindings);
            // Polygons as lists of corner starts (indices into the p list).
            let mut polys: Vec<Vec<usize>> = Vec::new();
            let p_main: Vec<usize> = match (kind, child(prim, "p")) {
                ("triangles" | "polylist", Some(p)) => self.ints(p)?,
                _ => Vec::new(),
            };
            match kind {
                "triangles" => {
                    let n = p_main.len() / (3 * stride);
                    polys.extend((0..n).map(|t| (0..3).map(|k| (t * 3 + k) * stride).collect()));
                }
                "polylist" => {
                    let counts = match child(prim, "vcount") {
                        Some(v) => self.ints(v)?,
                        None => Vec::new(),
                    };
                    let mut at = 0;
                    for n in counts {
                        polys.push((at..at + n).map(|k| k * stride).collect());
                        at += n;
                    }
                }
                _ => {
                    // polygons, trifans, tristrips: one <p> per polygon,
                    // fan or strip.
                    for p in children(prim, "p") {
                        let p = self.ints(p)?;
                        let n = p.len() / stride;
                        let starts: Vec<usize> = (0..n).map(|k| k * stride).collect();
                        let local: Vec<Vec<usize>> = match kind {
                            "polygons" => vec![starts],
                            "trifans" => (1..n.saturating_sub(1))
                                .map(|k| vec![starts[0], starts[k], starts[k + 1]])
                                .collect(),
                            _ => (0..n.saturating_sub(2))
                                .map(|k| {
                                    if k % 2 == 0 {
                                        vec![starts[k], starts[k + 1], starts[k + 2]]
                                    } else {
                                        vec![starts[k + 1], starts[k], starts[k + 2]]
                                    }
                                })
                                .collect(),
                        };
                        self.emit(
                            &local, &p, v_off, &normals, &uvs, &v_normals, &v_uvs, base, n_pos,
                            &place, material, group,
                        );
                    }
                    continue;
                }
            }
            self.emit(
                &polys, &p_main, v_off, &normals, &uvs, &v_normals, &v_uvs, base, n_pos, &place,
                material, group,
            );
        }
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn emit(
        &mut self,
        polys: &[Vec<usize>],
        p: &[usize],
        v_off: usize,
        normals: &Option<(usize, (Vec<f64>, usize))>,
        uvs: &Option<(usize, (Vec<f64>, usize))>,
        v_normals: &Option<(Vec<f64>, usize)>,
        v_uvs: &Option<(Vec<f64>, usize)>,
        base: u32,
        n_pos: usize,
        place: &Placement,
        material: u32,
        group: u32,
    ) {
        let normal_at = |src: &(Vec<f64>, usize), i: usize| -> Option<DVec3> {
            let (v, s) = src;
            (*s >= 3 && (i + 1) * s <= v.len())
                .then(|| place.normal(DVec3::new(v[i * s], v[i * s + 1], v[i * s + 2])))
        };
        let uv_at = |src: &(Vec<f64>, usize), i: usize| -> Option<DVec2> {
            let (v, s) = src;
            (*s >= 2 && (i + 1) * s <= v.len()).then(|| DVec2::new(v[i * s], v[i * s + 1]))
        };
        let mut dropped = 0usize;
        for poly in polys {
            let mut idx = Vec::with_capacity(poly.len());
            let mut nv = Vec::with_capacity(poly.len());
            let mut tv = Vec::with_capacity(poly.len());
            let mut bad = false;
            for &s in poly {
                let Some(&vi) = p.get(s + v_off) else {
                    bad = true;
                    break;
                };
                if vi >= n_pos {
                    bad = true;
                    break;
                }
                idx.push(base + vi as u32);
                let n = match normals {
                    Some((o, src)) => p.get(s + o).and_then(|&i| normal_at(src, i)),
                    None => v_normals.as_ref().and_then(|src| normal_at(src, vi)),
                };
                let t = match uvs {
                    Some((o, src)) => p.get(s + o).and_then(|&i| uv_at(src, i)),
                    None => v_uvs.as_ref().and_then(|src| uv_at(src, vi)),
                };
                nv.push(n);
                tv.push(t);
            }
            if bad {
                dropped += 1;
                continue;
            }
            if place.mirrors() {
                idx.reverse();
                nv.reverse();
                tv.reverse();
            }
            let normals: Option<Vec<DVec3>> = nv.into_iter().collect();
            let uvs: Option<Vec<DVec2>> = tv.into_iter().collect();
            if !self
                .b
                .polygon(&idx, uvs.as_deref(), normals.as_deref(), material, group)
            {
                dropped += 1;
            }
        }
        if dropped > 0 {
            self.warnings.push(format!(
                "{dropped} polygon(s) with indices out of range or fewer than 3 corners skipped"
            ));
        }
    }

    /// The material slot of a primitive's material symbol, through the
    /// instance's bindings (made once per COLLADA material).
    fn material_slot(&mut self, symbol: Option<&str>, bindings: &HashMap<String, String>) -> u32 {
        let id = symbol
            .map(|s| bindings.get(s).cloned().unwrap_or_else(|| s.to_string()))
            .unwrap_or_default();
        if let Some(&slot) = self.materials.get(&id) {
            return slot;
        }
        let m = self
            .ids
            .get(id.as_str())
            .copied()
            .filter(|n| n.tag_name().name() == "material")
            .map(|n| self.read_material(n))
            .unwrap_or_default();
        let slot = self.b.material(m);
        self.materials.insert(id, slot);
        slot
    }

    fn read_material(&self, n: Node) -> Material {
        let mut m = Material {
            name: Arc::from(n.attribute("name").or(n.attribute("id")).unwrap_or("")),
            ..Material::default()
        };
        let Some(effect) = child(n, "instance_effect").and_then(|i| self.target(i, "url")) else {
            return m;
        };
        let Some(profile) = child(effect, "profile_COMMON") else {
            return m;
        };
        let Some(technique) = child(profile, "technique").and_then(|t| {
            t.children().find(|c| {
                matches!(
                    c.tag_name().name(),
                    "phong" | "lambert" | "blinn" | "constant"
                )
            })
        }) else {
            return m;
        };
        let Some(diffuse) = child(technique, "diffuse") else {
            return m;
        };
        if let Some(c) = child(diffuse, "color") {
            if let Ok(v) = numbers(c.text().unwrap_or("")) {
                if v.len() >= 3 {
                    m.color = [v[0], v[1], v[2]].map(|x| x.clamp(0.0, 1.0));
                }
            }
        }
        if let Some(t) = child(diffuse, "texture").and_then(|t| t.attribute("texture")) {
            if let Some(file) = self.image_of_sampler(profile, t) {
                m.maps[0].path = Arc::from(file.as_str());
            }
        }
        m
    }

    /// The image file a `<texture texture="sampler">` shows: through the
    /// profile's sampler and surface parameters (COLLADA 1.4), an
    /// `instance_image` (1.5), or the image id itself (as some exporters
    /// write it).
    fn image_of_sampler(&self, profile: Node, sampler: &str) -> Option<String> {
        let param =
            |sid: &str| children(profile, "newparam").find(|p| p.attribute("sid") == Some(sid));
        let mut image_id = sampler.to_string();
        if let Some(s2d) = param(sampler).and_then(|p| child(p, "sampler2D")) {
            if let Some(img) = child(s2d, "instance_image").and_then(|i| self.target(i, "url")) {
                return self.image_file(img);
            }
            if let Some(src) = child(s2d, "source").and_then(|s| s.text()) {
                image_id = match param(src.trim())
                    .and_then(|p| child(p, "surface"))
                    .and_then(|s| child(s, "init_from"))
                    .and_then(|i| i.text())
                {
                    Some(id) => id.trim().to_string(),
                    None => src.trim().to_string(),
                };
            }
        }
        let img = self.ids.get(image_id.as_str()).copied()?;
        self.image_file(img)
    }

    fn image_file(&self, img: Node) -> Option<String> {
        let init = child(img, "init_from")?;
        let text = child(init, "ref").and_then(|r| r.text()).or(init.text())?;
        let text = text.trim();
        let path = text.strip_prefix("file://").unwrap_or(text);
        let path = percent_decode(path);
        if path.is_empty() {
            return None;
        }
        let p = Path::new(&path);
        let full = if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.dir.join(p)
        };
        Some(full.to_string_lossy().into_owned())
    }
}

/// `instance_material` bindings of an instance: symbol to material id.
fn bindings(inst: Node) -> HashMap<String, String> {
    child(inst, "bind_material")
        .and_then(|b| child(b, "technique_common"))
        .map(|t| {
            children(t, "instance_material")
                .filter_map(|m| {
                    Some((
                        m.attribute("symbol")?.to_string(),
                        m.attribute("target")?.trim_start_matches('#').to_string(),
                    ))
                })
                .collect()
        })
        .unwrap_or_default()
}

fn child<'a, 'i>(n: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
    n.children().find(|c| c.tag_name().name() == name)
}

fn children<'a, 'i: 'a>(n: Node<'a, 'i>, name: &'a str) -> impl Iterator<Item = Node<'a, 'i>> + 'a {
    n.children().filter(move |c| c.tag_name().name() == name)
}

fn line_of(doc: &Document, n: Node) -> usize {
    doc.text_pos_at(n.range().start).row as usize
}

/// Whitespace-separated numbers; the first token that is not a finite
/// number is the error.
fn numbers(text: &str) -> Result<Vec<f64>, String> {
    text.split_ascii_whitespace()
        .map(|t| match t.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(t.to_string()),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{bounds, face_normal, mesh_area, volume};

    /// A unit right triangle in the xy-plane (normal +z), instanced by the
    /// nodes given, with the primitive element given.
    fn doc(nodes: &str, prim: &str) -> String {
        format!(
            r##"<COLLADA version="1.4.1"><library_geometries><geometry id="g"><mesh>
<source id="p"><float_array count="12">0 0 0 1 0 0 1 1 0 0 1 0</float_array>
<technique_common><accessor count="4" stride="3"/></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
{prim}</mesh></geometry></library_geometries>
<library_nodes><node id="lib"><instance_geometry url="#g"/></node></library_nodes>
<library_visual_scenes><visual_scene id="s">{nodes}</visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#s"/></scene></COLLADA>"##
        )
    }

    const TRI: &str = r##"<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>"##;

    fn parse(text: &str) -> Mesh {
        parse_collada(text, Path::new("")).unwrap().mesh
    }

    use crate::mesh::Mesh;

    #[test]
    fn matrix_rotate_and_instance_node() {
        // A row-major matrix translating by (5, 6, 7).
        let m = parse(&doc(
            r##"<node><matrix>1 0 0 5 0 1 0 6 0 0 1 7 0 0 0 1</matrix><instance_geometry url="#g"/></node>"##,
            TRI,
        ));
        let (lo, hi) = bounds(&m).unwrap();
        assert_eq!(
            (lo, hi),
            (DVec3::new(5.0, 6.0, 7.0), DVec3::new(6.0, 7.0, 7.0))
        );
        // rotate 90 degrees about x: the normal +z turns to -y; through a
        // library node.
        let m = parse(&doc(
            r##"<node><rotate>1 0 0 90</rotate><instance_node url="#lib"/></node>"##,
            TRI,
        ));
        let n = face_normal(&m, 0);
        assert!((n - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-12, "{n}");
        // Two instances: two faces.
        let m = parse(&doc(
            r##"<node><instance_geometry url="#g"/></node><node><translate>0 0 2</translate><instance_geometry url="#g"/></node>"##,
            TRI,
        ));
        assert_eq!(m.faces.len(), 2);
    }

    #[test]
    fn a_mirroring_scale_keeps_faces_outward() {
        let m = parse(&doc(
            r##"<node><scale>-1 1 1</scale><instance_geometry url="#g"/></node>"##,
            TRI,
        ));
        assert!((face_normal(&m, 0) - DVec3::Z).length() < 1e-12);
    }

    #[test]
    fn polygons_fans_and_strips() {
        let q = r##"<polygons count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2 3</p></polygons>"##;
        let m = parse(&doc(r##"<node><instance_geometry url="#g"/></node>"##, q));
        assert_eq!(m.faces.len(), 1);
        assert!((mesh_area(&m) - 1.0).abs() < 1e-12);
        let f = r##"<trifans count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2 3</p></trifans>"##;
        let m = parse(&doc(r##"<node><instance_geometry url="#g"/></node>"##, f));
        assert_eq!(m.faces.len(), 2);
        assert!((mesh_area(&m) - 1.0).abs() < 1e-12);
        let s = r##"<tristrips count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 3 2</p></tristrips>"##;
        let m = parse(&doc(r##"<node><instance_geometry url="#g"/></node>"##, s));
        assert_eq!(m.faces.len(), 2);
        for f in 0..2 {
            assert!((face_normal(&m, f) - DVec3::Z).length() < 1e-12);
        }
        assert_eq!(volume(&m), 0.0);
    }

    #[test]
    fn errors_name_the_line() {
        let e = parse_collada(
            "<COLLADA>\n<asset>\n<unit meter=\"x\"/>\n</assets></COLLADA>",
            Path::new(""),
        );
        assert!(matches!(e, Err(ObjError::Parse { line: 4, .. })), "{e:?}");
        let e = parse_collada(
            &doc(r##"<node><translate>1 two 3</translate></node>"##, TRI),
            Path::new(""),
        );
        assert!(
            matches!(&e, Err(ObjError::Parse { message, .. }) if message.contains("two")),
            "{e:?}"
        );
        let e = parse_collada("<scene/>", Path::new(""));
        assert!(e.is_err());
        // Indices out of range are skipped with a warning.
        let bad = r##"<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 9</p></triangles>"##;
        let a = parse_collada(
            &doc(r##"<node><instance_geometry url="#g"/></node>"##, bad),
            Path::new(""),
        )
        .unwrap();
        assert_eq!(a.mesh.faces.len(), 0);
        assert_eq!(a.warnings.len(), 1);
    }
}
