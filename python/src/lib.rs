//! The native half of the Python package `cga`: a thin layer over the
//! engine's library facade (`crates/cga`). It loads rules, turns lots given
//! as numpy rings into engine lots, generates them (in parallel, with the
//! GIL released, interruptible by Ctrl-C) and hands results back as plain
//! Python data with numpy arrays that take over the engine's buffers.
//!
//! The Pythonic API (shapely, GeoPandas, GeoJSON, tqdm, trimesh, Dask) is
//! in `cga/*.py`; everything here takes and gives simple types, so that the
//! Python side can change without rebuilding.

use std::path::PathBuf;
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

use numpy::ndarray::Array2;
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList, PyString, PyTuple};
use pyo3::IntoPyObjectExt;

use cga::lots::Axes;
use cga::{
    Array, Cancel, DiskWorld, Engine, Error, Format, Limits, LotResult, Material, MemoryWorld,
    ModelWriter, Options, PlainMesh, PlainModel, Rules, Severity, Target, Value, World,
};

/// What `generate` gives: a dict per lot, the writer's counts, and the
/// lots left out as `(index, name, why)`.
type Generated<'py> = (
    Vec<Bound<'py, PyDict>>,
    Option<Bound<'py, PyDict>>,
    Vec<(usize, String, String)>,
);

/// A kept mesh given back for writing: material, positions, normals,
/// uvs, indices.
type MeshIn<'py> = (
    usize,
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray2<'py, u32>,
);

/// Loaded rules, shared by every generation that uses them.
#[pyclass(frozen, module = "cga._cga")]
struct NativeRules {
    rules: Rules,
}

/// The materials of one generated lot, kept as the engine has them so that
/// writing a model later loses nothing (textures and their transforms).
#[pyclass(frozen, module = "cga._cga")]
struct Materials {
    materials: Vec<Material>,
}

#[pymethods]
impl Materials {
    fn __len__(&self) -> usize {
        self.materials.len()
    }

    /// The materials as dictionaries.
    fn to_dicts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let dicts = self
            .materials
            .iter()
            .map(|m| material_dict(py, m))
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, dicts)
    }
}

fn engine(workspaces: Vec<PathBuf>, world: Arc<dyn World>) -> Engine {
    let engine = Engine::with_world(world);
    if workspaces.is_empty() {
        engine
    } else {
        engine.workspaces(cga::Workspaces::new(workspaces))
    }
}

/// Loads a rule file (`.cga`) or rule package (`.rpk`) from disk.
#[pyfunction]
#[pyo3(signature = (path, workspaces))]
fn load(py: Python<'_>, path: PathBuf, workspaces: Vec<PathBuf>) -> NativeRules {
    let rules = py.detach(|| engine(workspaces, Arc::new(DiskWorld)).load(&path));
    NativeRules { rules }
}

/// Loads rule text as the file `path`; `files` (path to bytes) are served
/// from memory, over the disk when `disk` is true.
#[pyfunction]
#[pyo3(signature = (path, text, files, disk, workspaces))]
fn load_text(
    py: Python<'_>,
    path: PathBuf,
    text: String,
    files: Vec<(PathBuf, Vec<u8>)>,
    disk: bool,
    workspaces: Vec<PathBuf>,
) -> NativeRules {
    let rules = py.detach(|| {
        let mut world = if disk {
            MemoryWorld::over(Arc::new(DiskWorld))
        } else {
            MemoryWorld::new()
        };
        for (p, bytes) in files {
            world = world.with(p, bytes);
        }
        engine(workspaces, Arc::new(world)).load_text(&path, text)
    });
    NativeRules { rules }
}

#[pymethods]
impl NativeRules {
    #[getter]
    fn path(&self) -> PathBuf {
        self.rules.path().to_path_buf()
    }

    #[getter]
    fn has_errors(&self) -> bool {
        self.rules.has_errors()
    }

    fn diagnostics<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.rules
            .diagnostics()
            .iter()
            .map(|d| diagnostic_dict(py, d))
            .collect()
    }

    /// The attributes: name, type, default, annotations, place, comment.
    fn attributes<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.rules
            .attributes()
            .iter()
            .map(|a| {
                let d = PyDict::new(py);
                d.set_item("name", &a.name)?;
                d.set_item("type", a.ty.map(|t| t.name()))?;
                d.set_item(
                    "default",
                    a.default.as_ref().map(|v| value_py(py, v)).transpose()?,
                )?;
                let annotations = a
                    .annotations
                    .iter()
                    .map(|an| {
                        let args = an
                            .args
                            .iter()
                            .map(|(n, v)| {
                                let v = v.as_ref().map(|v| value_py(py, v)).transpose()?;
                                (n.clone(), v).into_py_any(py)
                            })
                            .collect::<PyResult<Vec<_>>>()?;
                        (an.name.clone(), args).into_py_any(py)
                    })
                    .collect::<PyResult<Vec<_>>>()?;
                d.set_item("annotations", annotations)?;
                d.set_item("doc", &a.doc)?;
                if let Some(l) = &a.location {
                    d.set_item("file", &l.file)?;
                    d.set_item("line", l.line)?;
                }
                Ok(d)
            })
            .collect()
    }

    fn start_rules(&self) -> Vec<String> {
        self.rules.start_rules()
    }

    fn styles(&self) -> Vec<String> {
        self.rules.styles().to_vec()
    }

    /// The names lots may set (the attributes, and `seed`).
    fn attribute_names(&self) -> Vec<String> {
        self.rules
            .attributes()
            .iter()
            .map(|a| a.name.clone())
            .collect()
    }

    /// Generates `lots`: each `(name, polygons, gis_axes, attrs)` with
    /// polygons as lists of `(n, 3)` float64 rings. `geometry`: keep plain
    /// meshes (`"meshes"`), positions and triangles alone (`"positions"`)
    /// or none (`"none"`); `output`: write the models into this file
    /// instead (streamed).
    /// `progress(done)` is called on this thread at most ten times a second.
    /// `first_index`: the index of the first lot in a larger run (a Dask
    /// partition's place): lots then get the seeds they have in that run.
    /// `skip_invalid`: lots that cannot be made are left out and listed,
    /// instead of raising `ValueError`.
    /// Returns `(models, stats, invalid)`: a dict per lot, what the writer
    /// wrote, and `(index, name, why)` of each lot left out.
    #[pyo3(signature = (lots, attrs, seed, start_rule, jobs, geometry, output, progress, limits, first_index, skip_invalid))]
    #[allow(clippy::too_many_arguments)]
    fn generate<'py>(
        &self,
        py: Python<'py>,
        lots: &Bound<'py, PyList>,
        attrs: Vec<(String, Bound<'py, PyAny>)>,
        seed: u64,
        start_rule: Option<String>,
        jobs: Option<usize>,
        geometry: &str,
        output: Option<PathBuf>,
        progress: Option<Bound<'py, PyAny>>,
        limits: Option<(usize, usize, f64, usize)>,
        first_index: usize,
        skip_invalid: bool,
    ) -> PyResult<Generated<'py>> {
        let rules = &self.rules;
        if rules.has_errors() {
            // (The Python side raises RuleError, with the diagnostics, first.)
            let errors = rules.diagnostics().iter().filter(|d| d.is_error()).count();
            return Err(to_py_err(Error::Rules {
                path: rules.path().to_path_buf(),
                errors,
            }));
        }
        let (lots, places, invalid) = read_lots(rules, lots, skip_invalid)?;
        // Each lot derives with its place in the whole run (its seed, its
        // number in context queries), also when it is a part of a run
        // (`first_index`) or lots before it were left out: the facade's
        // `Options::lot_indices`.
        let indices: Arc<[usize]> = places.iter().map(|&p| first_index + p).collect();
        let mut options = Options::default().seed(seed);
        options.start_rule = start_rule;
        options.lot_indices = Some(indices);
        for (name, value) in attrs {
            if let Some(v) = py_value(&value)? {
                options = options.attr(name, v);
            }
        }
        if let Some(j) = jobs {
            options = options.jobs(j);
        }
        if let Some((depth, shapes, seconds, faces)) = limits {
            options = options.limits(Limits {
                max_depth: depth,
                max_shapes: shapes,
                max_seconds: seconds,
                max_faces: faces,
            });
        }
        // Refused options are refused before any thread starts.
        rules.check_attributes(&options).map_err(to_py_err)?;
        rules
            .start_rule(options.start_rule.as_deref())
            .map_err(to_py_err)?;
        let format = match &output {
            Some(path) => Some(Format::from_path(path).ok_or_else(|| {
                PyValueError::new_err(format!(
                    "{}: the model file must end in .glb, .gltf or .obj",
                    path.display()
                ))
            })?),
            None => None,
        };
        let cancel = Cancel::new();
        options = options.cancel(cancel.clone());

        // The generation runs on a thread of its own while this thread,
        // holding the GIL only between waits, turns results into Python
        // objects as they come (in lot order), updates the progress and
        // looks for Ctrl-C: a signal cancels the generation, which stops
        // within milliseconds.
        let (tx, rx) = mpsc::channel::<LotResult>();
        let rx = Mutex::new(rx);
        let target = match (geometry, &output) {
            (_, Some(_)) | ("none", _) => Target::Nothing,
            ("meshes", None) => Target::Meshes,
            ("positions", None) => Target::Positions,
            (other, None) => {
                return Err(PyValueError::new_err(format!(
                    "geometry must be True, False or \"positions\", not {other:?}"
                )))
            }
        };
        let positions_only = matches!(target, Target::Positions);
        let run = || -> Result<Option<cga::ExportStats>, Error> {
            let tx = tx;
            let send = |r: LotResult| {
                // A closed channel: the caller stopped listening (an error
                // converting a result); the cancel flag stops the rest.
                let _ = tx.send(r);
            };
            match (&output, format) {
                (Some(path), Some(format)) => {
                    let export = cga::ExportOptions {
                        origin: cga::lots::local_origin(&lots),
                        ..rules.export_options()
                    };
                    let mut writer = ModelWriter::create(path, format, export)?;
                    rules.generate_lots(&lots, &options, Target::Writer(&mut writer), send)?;
                    Ok(Some(writer.finish()?))
                }
                _ => {
                    rules.generate_lots(&lots, &options, target, send)?;
                    Ok(None)
                }
            }
        };
        let total = lots.len();
        let mut models = Vec::with_capacity(total);
        let mut failure: Option<PyErr> = None;
        let mut last_progress = Instant::now();
        let outcome = std::thread::scope(|s| {
            let worker = std::thread::Builder::new()
                .name("cga-generate".into())
                .spawn_scoped(s, run)
                .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
            loop {
                let got = py.detach(|| {
                    let rx = rx.lock().unwrap_or_else(|e| e.into_inner());
                    rx.recv_timeout(Duration::from_millis(50))
                });
                match got {
                    Ok(result) => {
                        if failure.is_none() {
                            match model_dict(py, result, positions_only) {
                                Ok(d) => models.push(d),
                                Err(e) => {
                                    cancel.cancel();
                                    failure = Some(e);
                                }
                            }
                        }
                    }
                    Err(mpsc::RecvTimeoutError::Timeout) => {}
                    Err(mpsc::RecvTimeoutError::Disconnected) => break,
                }
                if failure.is_none() {
                    if let Err(e) = py.check_signals() {
                        cancel.cancel();
                        failure = Some(e);
                    }
                }
                if let (Some(p), None) = (&progress, &failure) {
                    if last_progress.elapsed() >= Duration::from_millis(100) {
                        last_progress = Instant::now();
                        if let Err(e) = p.call1((models.len(), total)) {
                            cancel.cancel();
                            failure = Some(e);
                        }
                    }
                }
            }
            let joined = py.detach(|| worker.join());
            joined.map_err(|_| PyRuntimeError::new_err("the generation thread panicked"))
        })?;
        if let Some(e) = failure {
            return Err(e);
        }
        let stats = outcome.map_err(to_py_err)?;
        if let Some(p) = &progress {
            p.call1((models.len(), total))?;
        }
        let stats = match stats {
            Some(s) => {
                let d = PyDict::new(py);
                d.set_item("faces", s.faces)?;
                d.set_item("triangles", s.triangles)?;
                d.set_item("warnings", &s.warnings)?;
                Some(d)
            }
            None => None,
        };
        let invalid = invalid
            .into_iter()
            .map(|(i, name, why)| (first_index + i, name, why))
            .collect();
        Ok((models, stats, invalid))
    }
}

/// Engine lots from the Python side's tuples, checked: a bad lot is a
/// `ValueError` naming its index, or, with `skip`, left out and listed as
/// `(index, name, why)`. Also gives each lot's index among `lots`.
#[allow(clippy::type_complexity)]
fn read_lots(
    rules: &Rules,
    lots: &Bound<'_, PyList>,
    skip: bool,
) -> PyResult<(Vec<cga::Lot>, Vec<usize>, Vec<(usize, String, String)>)> {
    let mut out = Vec::with_capacity(lots.len());
    let mut places = Vec::with_capacity(lots.len());
    let mut invalid = Vec::new();
    for (i, item) in lots.iter().enumerate() {
        match read_lot(rules, i, &item) {
            Ok(lot) => {
                out.push(lot);
                places.push(i);
            }
            Err((name, why)) if skip => invalid.push((i, name, why)),
            Err((name, why)) => {
                return Err(PyValueError::new_err(format!("lot {i} ({name}): {why}")))
            }
        }
    }
    Ok((out, places, invalid))
}

/// One lot, or its name and why it cannot be made (`(name, why)`: a lot
/// the Python side found invalid).
fn read_lot(
    rules: &Rules,
    i: usize,
    item: &Bound<'_, PyAny>,
) -> Result<cga::Lot, (String, String)> {
    if let Ok((name, why)) = item.extract::<(String, String)>() {
        return Err((name, why));
    }
    type Item<'py> = (
        String,
        Vec<Vec<PyReadonlyArray2<'py, f64>>>,
        bool,
        Vec<(String, Bound<'py, PyAny>)>,
    );
    let (name, polygons, gis, attrs): Item<'_> = item
        .extract()
        .map_err(|e| (format!("{i}"), format!("not a lot the package made: {e}")))?;
    let bad = |why: String| (name.clone(), why);
    let mut rings_of = Vec::with_capacity(polygons.len());
    for polygon in &polygons {
        let mut rings = Vec::with_capacity(polygon.len());
        for ring in polygon {
            let a = ring.as_array();
            if a.ncols() != 3 {
                return Err(bad(format!(
                    "a ring must be an (n, 3) array of coordinates, not ({}, {})",
                    a.nrows(),
                    a.ncols()
                )));
            }
            rings.push(
                a.rows()
                    .into_iter()
                    .map(|r| [r[0], r[1], r[2]])
                    .collect::<Vec<_>>(),
            );
        }
        rings_of.push(rings);
    }
    let axes = if gis { Axes::Gis } else { Axes::Engine };
    let mut lot = cga::lots::from_polygons(name.clone(), &rings_of, axes).map_err(bad)?;
    for (attr, value) in attrs {
        if attr != "seed" && rules.attribute(&attr).is_none() {
            return Err(bad(Error::UnknownAttribute {
                name: attr,
                known: rules.attributes().iter().map(|a| a.name.clone()).collect(),
            }
            .to_string()));
        }
        let value = py_value(&value).map_err(|e| bad(format!("attribute `{attr}`: {e}")))?;
        if let Some(v) = value {
            lot.attrs.push((Arc::from(attr.as_str()), v));
        }
    }
    Ok(lot)
}

/// A Python value as a CGA value: bool, number, string, or a sequence of
/// one of them (a CGA array). `None` (and NaN, a frame's missing value)
/// is no value: the attribute keeps its default.
fn py_value(v: &Bound<'_, PyAny>) -> PyResult<Option<Value>> {
    use cga::Value as V;
    if v.is_none() {
        return Ok(None);
    }
    if let Ok(b) = v.cast::<PyBool>() {
        return Ok(Some(V::Bool(b.is_true())));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(Some(V::from(s.to_cow()?.as_ref())));
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok((!x.is_nan()).then_some(V::Float(x)));
    }
    if let Ok(xs) = v.extract::<Vec<bool>>() {
        return Ok(Some(Value::from(Array::row(xs))));
    }
    if let Ok(xs) = v.extract::<Vec<f64>>() {
        return Ok(Some(Value::from(Array::row(xs))));
    }
    if let Ok(xs) = v.extract::<Vec<String>>() {
        let xs: Vec<Arc<str>> = xs.iter().map(|s| Arc::from(s.as_str())).collect();
        return Ok(Some(Value::from(Array::row(xs))));
    }
    Err(PyValueError::new_err(format!(
        "{} is not a value CGA has (a bool, number, string, or a list of one of them)",
        v.repr()?
    )))
}

fn value_py(py: Python<'_>, v: &Value) -> PyResult<Py<PyAny>> {
    match v {
        Value::Float(x) => x.into_py_any(py),
        Value::Bool(b) => b.into_py_any(py),
        Value::Str(s) => (**s).into_py_any(py),
        Value::FloatArray(a) => a.data.clone().into_py_any(py),
        Value::BoolArray(a) => a.data.clone().into_py_any(py),
        Value::StrArray(a) => a
            .data
            .iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .into_py_any(py),
    }
}

fn diagnostic_dict<'py>(py: Python<'py>, d: &cga::Diagnostic) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item(
        "severity",
        match d.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        },
    )?;
    out.set_item("message", &d.message)?;
    out.set_item("label", &d.label)?;
    out.set_item("notes", &d.notes)?;
    out.set_item("rendered", d.render())?;
    if let Some(l) = &d.location {
        out.set_item("file", &l.file)?;
        out.set_item("line", l.line)?;
        out.set_item("column", l.column)?;
        out.set_item("end_line", l.end_line)?;
        out.set_item("end_column", l.end_column)?;
        out.set_item("line_text", &l.line_text)?;
    }
    Ok(out)
}

fn material_dict<'py>(py: Python<'py>, m: &Material) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", &*m.name)?;
    d.set_item("color", m.color)?;
    d.set_item("opacity", m.opacity)?;
    d.set_item("metallic", m.metallic)?;
    d.set_item("roughness", m.roughness)?;
    d.set_item("emissive", m.emissive)?;
    d.set_item("double_sided", m.double_sided)?;
    let textures = PyDict::new(py);
    for (channel, map) in cga::TEXTURE_CHANNELS.iter().zip(&m.maps) {
        if !map.path.is_empty() {
            textures.set_item(*channel, &*map.path)?;
        }
    }
    d.set_item("textures", textures)?;
    Ok(d)
}

/// `Vec<[T; N]>` as a flat `Vec<T>`, without copying: both have the
/// same allocation layout (size `N * size_of::<T>()` per element, the
/// alignment of `T`).
fn flatten<T, const N: usize>(v: Vec<[T; N]>) -> Vec<T> {
    let mut v = std::mem::ManuallyDrop::new(v);
    let (ptr, len, cap) = (v.as_mut_ptr(), v.len(), v.capacity());
    // SAFETY: `[T; N]` is N `T`s laid out contiguously with `T`'s
    // alignment, so the allocation of `cap` arrays is one of `cap * N`
    // `T`s with the same layout, and the first `len * N` are initialised.
    unsafe { Vec::from_raw_parts(ptr as *mut T, len * N, cap * N) }
}

/// An `(n, N)` numpy array that owns the engine's buffer (no copy).
fn array<'py, T: numpy::Element, const N: usize>(
    py: Python<'py>,
    v: Vec<[T; N]>,
) -> Bound<'py, PyArray2<T>> {
    let n = v.len();
    let a = Array2::from_shape_vec((n, N), flatten(v)).expect("n rows of N");
    PyArray2::from_owned_array(py, a)
}

/// A lot's result as a dict (its index: its place in the whole run).
/// `positions_only`: its meshes have no normals or texture coordinates
/// (given as None).
fn model_dict(py: Python<'_>, r: LotResult, positions_only: bool) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("index", r.index)?;
    d.set_item("name", &r.name)?;
    d.set_item("prints", &r.prints)?;
    let reports = r
        .reports
        .iter()
        .map(|(k, v)| (k.clone(), value_py(py, v)?).into_py_any(py))
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("reports", reports)?;
    let warnings: Vec<&str> = r.warnings.iter().map(|w| w.message.as_str()).collect();
    d.set_item("warnings", warnings)?;
    d.set_item(
        "error",
        r.error
            .as_ref()
            .map(|e| diagnostic_dict(py, e))
            .transpose()?,
    )?;
    d.set_item("shapes", r.shapes)?;
    d.set_item("leaves", r.leaf_count)?;
    d.set_item("written", r.triangles_written)?;
    let PlainModel {
        materials, meshes, ..
    } = r.model;
    let meshes = meshes
        .into_iter()
        .map(|m| {
            let PlainMesh {
                material,
                positions,
                normals,
                uvs,
                indices,
                ..
            } = m;
            let (normals, uvs) = match positions_only {
                true => (py.None(), py.None()),
                false => (
                    array(py, normals).into_any().unbind(),
                    array(py, uvs).into_any().unbind(),
                ),
            };
            PyTuple::new(
                py,
                [
                    material.into_py_any(py)?,
                    array(py, positions).into_any().unbind(),
                    normals,
                    uvs,
                    array(py, indices).into_any().unbind(),
                ],
            )
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("meshes", meshes)?;
    d.set_item("materials", Py::new(py, Materials { materials })?)?;
    Ok(d)
}

/// Writes kept models into one file: each `(materials, meshes)` with
/// meshes as `(material, positions, normals, uvs, indices)`. Textures are
/// looked for as `rules` would (beside its rule file).
#[pyfunction]
#[pyo3(signature = (path, rules, models))]
fn write<'py>(
    py: Python<'py>,
    path: PathBuf,
    rules: Option<&NativeRules>,
    models: &Bound<'py, PyList>,
) -> PyResult<Bound<'py, PyDict>> {
    let format = Format::from_path(&path).ok_or_else(|| {
        PyValueError::new_err(format!(
            "{}: the model file must end in .glb, .gltf or .obj",
            path.display()
        ))
    })?;
    let options = match rules {
        Some(r) => r.rules.export_options(),
        None => cga::ExportOptions::default(),
    };
    // Far from the frame's origin (a national grid's metres), glTF's
    // 32-bit floats need a local origin: the models' centre.
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for item in models.iter() {
        let (_, meshes): (Bound<'_, Materials>, Vec<MeshIn<'_>>) = item.extract()?;
        for (_, positions, ..) in &meshes {
            for row in positions.as_array().rows() {
                for k in 0..row.len().min(3) {
                    lo[k] = lo[k].min(row[k]);
                    hi[k] = hi[k].max(row[k]);
                }
            }
        }
    }
    let origin = (lo[0] <= hi[0])
        .then(|| cga::lots::origin_of_box(cga::DVec3::from(lo), cga::DVec3::from(hi)))
        .flatten();
    let options = cga::ExportOptions { origin, ..options };
    let mut writer =
        ModelWriter::create(&path, format, options).map_err(|e| to_py_err(e.into()))?;
    for item in models.iter() {
        let (materials, meshes): (Bound<'_, Materials>, Vec<MeshIn<'_>>) = item.extract()?;
        let rows3 = |a: &PyReadonlyArray2<'_, f64>| -> PyResult<Vec<[f64; 3]>> {
            let a = a.as_array();
            if a.ncols() != 3 {
                return Err(PyValueError::new_err(
                    "positions and normals are (n, 3) arrays",
                ));
            }
            Ok(a.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect())
        };
        let mut model = PlainModel {
            materials: materials.get().materials.clone(),
            ..PlainModel::default()
        };
        for (material, positions, normals, uvs, indices) in &meshes {
            let uvs = uvs.as_array();
            let indices = indices.as_array();
            if uvs.ncols() != 2 || indices.ncols() != 3 {
                return Err(PyValueError::new_err(
                    "uvs are (n, 2) arrays and indices (m, 3) arrays",
                ));
            }
            model.meshes.push(PlainMesh {
                material: *material,
                positions: rows3(positions)?,
                normals: rows3(normals)?,
                uvs: uvs.rows().into_iter().map(|r| [r[0], r[1]]).collect(),
                indices: indices
                    .rows()
                    .into_iter()
                    .map(|r| [r[0], r[1], r[2]])
                    .collect(),
                triangle_leaf: Vec::new(),
            });
        }
        py.detach(|| cga::write_plain(&mut writer, &model))
            .map_err(to_py_err)?;
    }
    let stats = py
        .detach(|| writer.finish())
        .map_err(|e| to_py_err(e.into()))?;
    let d = PyDict::new(py);
    d.set_item("faces", stats.faces)?;
    d.set_item("triangles", stats.triangles)?;
    d.set_item("warnings", &stats.warnings)?;
    Ok(d)
}

fn to_py_err(e: Error) -> PyErr {
    match e {
        Error::Export(_) | Error::Threads(_) => PyOSError::new_err(e.to_string()),
        Error::Cancelled => PyRuntimeError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// The engine's allocator for what the module allocates (the interpreter
/// keeps its own): lots' meshes, handed to numpy without a copy, come from
/// memory the lot before freed instead of fresh pages the kernel zeroes
/// (the system allocator maps blocks that large anew each time).
#[global_allocator]
static ALLOCATOR: cga_alloc::Allocator = cga_alloc::Allocator;

/// Memory freed is kept this long for the next lot and the next call,
/// then given back: a session that generated a city does not hold its peak
/// for good.
const KEEP_FREED: Duration = Duration::from_secs(10);

#[pymodule]
fn _cga(m: &Bound<'_, PyModule>) -> PyResult<()> {
    cga_alloc::keep_freed_memory(Some(KEEP_FREED));
    m.add_class::<NativeRules>()?;
    m.add_class::<Materials>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(load_text, m)?)?;
    m.add_function(wrap_pyfunction!(write, m)?)?;
    m.add("ENGINE_VERSION", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
