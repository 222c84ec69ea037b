//! Built-in functions that read files or convert coordinates: `convert`,
//! `assetInfo`, `imageInfo`, `readTextFile`, `readStringTable`,
//! `readFloatTable`, `fileExists`, `fileSearch`, `filesSearch`, `fileRandom`.
//! Files are searched like assets, from the rule file that calls the
//! function (see `assets.rs`).

use std::sync::Arc;

use cga_geometry::DVec3;
use cga_value::{Array, Value};

use crate::derive::{Interp, RtError};
use crate::expr::RExpr;
use crate::shape::{euler_to_mat, mat_to_euler, Frame, Shape};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileFn {
    Convert,
    AssetInfo,
    ImageInfo,
    ReadTextFile,
    ReadStringTable,
    ReadFloatTable,
    FileExists,
    FileSearch,
    FilesSearch,
    FileRandom,
    /// `edgeAttr.getFloat/getString/getBool(name)`: the lot's edge
    /// attributes.
    EdgeAttr(EdgeAttrType),
    /// `getGeoCoord(X|Y|lon|lat)`.
    GetGeoCoord,
    /// `assetsSortSize(files, axes, maxScaleError)`.
    AssetsSortSize,
    /// `assetsSortRatio(files, axes)`.
    AssetsSortRatio,
    /// `imagesSortRatio(files, axes)`.
    ImagesSortRatio,
    /// `assetMetadata(file, key, default)`.
    AssetMetadata,
    /// `sel(string)`: a selector from a string.
    Sel,
    /// `getTreeKey()`: the shape's path in the shape tree.
    TreeKey,
    /// Functions of CGA this engine does not compute: a warning and an
    /// empty result of the function's type, so that rule files using them
    /// still generate.
    Unsupported(Unsupported),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unsupported {
    /// `assetNamingInfo(..)`: a string.
    Str(&'static str),
    /// `assetNamingInfos(..)`, `getMaterial(..)`, `readMaterial(..)`: a
    /// string array.
    StrArray(&'static str),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeAttrType {
    Float,
    String,
    Bool,
}

pub fn lookup(name: &str, arity: usize) -> Option<FileFn> {
    Some(match (name, arity) {
        ("convert", 4 | 7) => FileFn::Convert,
        ("assetInfo", 2) => FileFn::AssetInfo,
        ("imageInfo", 2) => FileFn::ImageInfo,
        ("readTextFile", 1) => FileFn::ReadTextFile,
        ("readStringTable", 1) => FileFn::ReadStringTable,
        ("readFloatTable", 1) => FileFn::ReadFloatTable,
        ("fileExists", 1) => FileFn::FileExists,
        ("fileSearch", 1) => FileFn::FileSearch,
        ("filesSearch", 1) => FileFn::FilesSearch,
        ("fileRandom", 1) => FileFn::FileRandom,
        ("edgeAttr.getFloat", 1) => FileFn::EdgeAttr(EdgeAttrType::Float),
        ("edgeAttr.getString", 1) => FileFn::EdgeAttr(EdgeAttrType::String),
        ("edgeAttr.getBool", 1) => FileFn::EdgeAttr(EdgeAttrType::Bool),
        ("getGeoCoord", 1) => FileFn::GetGeoCoord,
        ("assetsSortSize", 3) => FileFn::AssetsSortSize,
        ("assetsSortRatio", 2) => FileFn::AssetsSortRatio,
        ("imagesSortRatio", 2) => FileFn::ImagesSortRatio,
        ("assetMetadata", 3) => FileFn::AssetMetadata,
        ("sel", 1) => FileFn::Sel,
        ("getTreeKey", 0) => FileFn::TreeKey,
        ("assetNamingInfo", 2) => FileFn::Unsupported(Unsupported::Str("assetNamingInfo")),
        ("assetNamingInfos", 2) => FileFn::Unsupported(Unsupported::StrArray("assetNamingInfos")),
        ("getMaterial", 1 | 2) => FileFn::Unsupported(Unsupported::StrArray("getMaterial")),
        ("readMaterial", 1) => FileFn::Unsupported(Unsupported::StrArray("readMaterial")),
        _ => return None,
    })
}

fn text<'a>(v: &'a Value, at: &RExpr) -> Result<&'a str, RtError> {
    match v {
        Value::Str(s) => Ok(s),
        other => Err(RtError::new(
            format!("expected a string, found {}", other.type_name()),
            at.span,
        )),
    }
}

fn num(v: &Value, at: &RExpr) -> Result<f64, RtError> {
    match v {
        Value::Float(x) => Ok(*x),
        other => Err(RtError::new(
            format!("expected a float, found {}", other.type_name()),
            at.span,
        )),
    }
}

impl Interp<'_> {
    pub(crate) fn file_fn(
        &mut self,
        f: FileFn,
        args: &[Value],
        shape: &Shape,
        at: &RExpr,
    ) -> Result<Value, RtError> {
        let file = at.span.file;
        Ok(match f {
            FileFn::Convert => self.convert(args, shape, at)?,
            // Lots carry no edge attribute arrays (`/edgeattr/NAME`): every
            // lookup gives the page's default for a missing attribute.
            FileFn::EdgeAttr(t) => {
                text(&args[0], at)?;
                match t {
                    EdgeAttrType::Float => Value::Float(0.0),
                    EdgeAttrType::String => Value::str(""),
                    EdgeAttrType::Bool => Value::Bool(false),
                }
            }
            FileFn::GetGeoCoord => {
                // The scope origin in scene coordinates: x is east and -z
                // north (metres); longitude and latitude need a lot given
                // in geographic coordinates.
                let o = shape.scope.frame.origin;
                let (east, north) = (o.x, -o.z);
                match text(&args[0], at)? {
                    "X" => Value::Float(east),
                    "Y" => Value::Float(north),
                    which @ ("lon" | "lat") => match self.info.geo_origin {
                        Some(g) => {
                            let (lon, lat) = g.to_geo(east, north);
                            Value::Float(if which == "lon" { lon } else { lat })
                        }
                        None => {
                            self.warn_once(at.span, || {
                                "getGeoCoord: the lot is not georeferenced (give lots in longitude/latitude); it returns nan".to_string()
                            });
                            Value::Float(f64::NAN)
                        }
                    },
                    other => {
                        return Err(RtError::new(
                            format!("unknown geo coordinate `{other}`: expected X, Y, lon or lat"),
                            at.span,
                        ))
                    }
                }
            }
            FileFn::AssetInfo => {
                let path = text(&args[0], at)?;
                let which = text(&args[1], at)?;
                let mesh = match self.assets.mesh(file, path) {
                    Ok(m) => m,
                    Err(e) => {
                        self.warn_once(at.span, || format!("{e}; assetInfo returns 0"));
                        return Ok(Value::Float(0.0));
                    }
                };
                let (lo, hi) = cga_geometry::measure::bounds(&mesh).unwrap_or_default();
                let k = |c: &str| match c {
                    "x" => 0,
                    "y" => 1,
                    _ => 2,
                };
                let split = if which.is_char_boundary(1) {
                    which.split_at(1)
                } else {
                    ("", which)
                };
                match split {
                    ("s", c) => Value::Float((hi - lo)[k(c)]),
                    ("t", c) => Value::Float(lo[k(c)]),
                    _ => {
                        return Err(RtError::new(
                            format!("unknown assetInfo attribute `{which}`: expected sx, sy, sz, tx, ty or tz"),
                            at.span,
                        ))
                    }
                }
            }
            FileFn::ImageInfo => {
                let path = text(&args[0], at)?;
                let which = text(&args[1], at)?;
                match self.assets.image_size(file, path) {
                    Some((w, h)) => Value::Float(if which == "sy" { h } else { w } as f64),
                    None => {
                        self.warn_once(at.span, || {
                            format!(
                                "image \"{path}\" not found or not readable; imageInfo returns 0"
                            )
                        });
                        Value::Float(0.0)
                    }
                }
            }
            FileFn::ReadTextFile => {
                let path = text(&args[0], at)?;
                match self.assets.text(file, path) {
                    Some(t) => Value::Str(t),
                    None => {
                        self.warn_once(at.span, || format!("text file \"{path}\" not found"));
                        Value::str("")
                    }
                }
            }
            FileFn::ReadStringTable | FileFn::ReadFloatTable => {
                let path = text(&args[0], at)?;
                let table = match self.assets.text(file, path) {
                    Some(t) => parse_table(&t),
                    None => {
                        self.warn_once(at.span, || format!("table file \"{path}\" not found"));
                        Array::row(Vec::new())
                    }
                };
                if f == FileFn::ReadStringTable {
                    Value::StrArray(Arc::new(table))
                } else {
                    Value::FloatArray(Arc::new(Array {
                        rows: table.rows,
                        cols: table.cols,
                        data: table
                            .data
                            .iter()
                            .map(|s| s.trim().parse::<f64>().unwrap_or(f64::NAN))
                            .collect(),
                    }))
                }
            }
            FileFn::FileExists => {
                Value::Bool(self.assets.resolve(file, text(&args[0], at)?).is_some())
            }
            FileFn::AssetsSortSize | FileFn::AssetsSortRatio | FileFn::ImagesSortRatio => {
                self.sort_files(f, args, shape, at)?
            }
            // Only OBJ assets are read, and OBJ carries no metadata: the
            // default value is the answer.
            FileFn::AssetMetadata => {
                text(&args[0], at)?;
                text(&args[1], at)?;
                args[2].clone()
            }
            FileFn::Sel => Value::Str(Arc::from(text(&args[0], at)?)),
            FileFn::TreeKey => Value::Str(self.tree_key.clone()),
            FileFn::Unsupported(u) => {
                let (name, value) = match u {
                    Unsupported::Str(n) => (n, Value::str("")),
                    Unsupported::StrArray(n) => {
                        (n, Value::StrArray(Arc::new(Array::row(Vec::new()))))
                    }
                };
                self.warn_once(at.span, || {
                    format!("the function `{name}` is not supported yet; it returns an empty value")
                });
                value
            }
            FileFn::FileSearch | FileFn::FilesSearch | FileFn::FileRandom => {
                let found = self.assets.search(file, text(&args[0], at)?);
                match f {
                    FileFn::FileSearch => Value::Str(Arc::from(
                        found.iter().map(|s| format!("{s};")).collect::<String>(),
                    )),
                    FileFn::FilesSearch => Value::StrArray(Arc::new(Array::row(
                        found.iter().map(|s| Arc::from(s.as_str())).collect(),
                    ))),
                    _ => {
                        if found.is_empty() {
                            Value::str("")
                        } else {
                            let i = (shape.next_random() * found.len() as f64) as usize;
                            Value::str(&found[i.min(found.len() - 1)])
                        }
                    }
                }
            }
        })
    }

    /// `assetsSortSize`, `assetsSortRatio`, `imagesSortRatio`: the files
    /// (a `;`-terminated list or a string array, answered in the same form)
    /// ordered by how well their size or aspect ratio fits the scope's, best
    /// first; ties keep the given order.
    fn sort_files(
        &mut self,
        f: FileFn,
        args: &[Value],
        shape: &Shape,
        at: &RExpr,
    ) -> Result<Value, RtError> {
        let file = at.span.file;
        let (files, as_list): (Vec<Arc<str>>, bool) = match &args[0] {
            Value::Str(s) => (
                s.split(';')
                    .filter(|p| !p.is_empty())
                    .map(Arc::from)
                    .collect(),
                true,
            ),
            Value::StrArray(a) => (a.data.to_vec(), false),
            other => {
                return Err(RtError::new(
                    format!(
                        "expected a file list or a string array, found {}",
                        other.type_name()
                    ),
                    at.span,
                ))
            }
        };
        let axes_text = text(&args[1], at)?;
        let axes: Vec<usize> = axes_text
            .chars()
            .map(|c| match c {
                'x' => Ok(0),
                'y' => Ok(1),
                'z' => Ok(2),
                _ => Err(()),
            })
            .collect::<Result<_, _>>()
            .ok()
            .filter(|a: &Vec<usize>| !a.is_empty())
            .ok_or_else(|| {
                RtError::new(
                    format!("unknown axes `{axes_text}`: expected x, y, z, xy, xz, yz or xyz"),
                    at.span,
                )
            })?;
        let scope = shape.scope.size.to_array();
        // Each file's size along x, y, z (images: width and height as the
        // two selected axes), or None when it cannot be read.
        let sizes: Vec<Option<[f64; 3]>> = files
            .iter()
            .map(|path| {
                if f == FileFn::ImagesSortRatio {
                    let (w, h) = self.assets.image_size(file, path)?;
                    let mut v = [0.0; 3];
                    v[axes[0]] = w as f64;
                    if let Some(&b) = axes.get(1) {
                        v[b] = h as f64;
                    }
                    Some(v)
                } else {
                    let mesh = self.assets.mesh(file, path).ok()?;
                    let (lo, hi) = cga_geometry::measure::bounds(&mesh)?;
                    Some((hi - lo).to_array())
                }
            })
            .collect();
        let max_error = match f {
            FileFn::AssetsSortSize => num(&args[2], at)?,
            _ => 0.0,
        };
        // How far a file is from fitting: for sizes, the largest relative
        // scaling it needs along the axes; for ratios, the largest factor
        // (as a logarithm) between its axis ratios and the scope's.
        let misfit = |size: [f64; 3]| -> f64 {
            if f == FileFn::AssetsSortSize {
                axes.iter()
                    .map(|&a| {
                        if size[a] > 0.0 {
                            (scope[a] / size[a] - 1.0).abs()
                        } else {
                            f64::INFINITY
                        }
                    })
                    .fold(0.0, f64::max)
            } else {
                axes.windows(2)
                    .map(|w| {
                        let ours = scope[w[0]] / scope[w[1]];
                        let theirs = size[w[0]] / size[w[1]];
                        let r = (ours / theirs).ln().abs();
                        if r.is_nan() {
                            f64::INFINITY
                        } else {
                            r
                        }
                    })
                    .fold(0.0, f64::max)
            }
        };
        let mut ranked: Vec<(f64, usize)> = Vec::with_capacity(files.len());
        for (i, size) in sizes.iter().enumerate() {
            match size {
                // Differences at rounding level (an asset written as
                // 0.999999999999999 wide) count as a perfect fit.
                Some(s) => ranked.push((Some(misfit(*s)).filter(|&e| e > 1e-9).unwrap_or(0.0), i)),
                None => {
                    let path = files[i].clone();
                    self.warn_once(at.span, || {
                        format!("\"{path}\" not found or not readable; it is sorted last")
                    });
                    ranked.push((f64::INFINITY, i));
                }
            }
        }
        ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
        let kept: Vec<Arc<str>> = ranked
            .into_iter()
            .filter(|&(e, _)| max_error <= 0.0 || e <= max_error)
            .map(|(_, i)| files[i].clone())
            .collect();
        Ok(if as_list {
            Value::Str(Arc::from(
                kept.iter().map(|s| format!("{s};")).collect::<String>(),
            ))
        } else {
            Value::StrArray(Arc::new(Array::row(kept)))
        })
    }

    /// `convert(coordinate, from, to, type, x, y, z)` and
    /// `convert(from, to, type, [x, y, z])`.
    fn convert(&mut self, args: &[Value], shape: &Shape, at: &RExpr) -> Result<Value, RtError> {
        let (component, rest) = if args.len() == 7 {
            (Some(text(&args[0], at)?), &args[1..])
        } else {
            (None, args)
        };
        let from = self.frame_of(text(&rest[0], at)?, shape, at)?;
        let to = self.frame_of(text(&rest[1], at)?, shape, at)?;
        let orient = match text(&rest[2], at)? {
            "orient" => true,
            "pos" => false,
            other => {
                return Err(RtError::new(
                    format!("unknown conversion type `{other}`: expected pos or orient"),
                    at.span,
                ))
            }
        };
        let v = if component.is_some() {
            DVec3::new(num(&rest[3], at)?, num(&rest[4], at)?, num(&rest[5], at)?)
        } else {
            match &rest[3] {
                Value::FloatArray(a) if a.data.len() == 3 => {
                    DVec3::new(a.data[0], a.data[1], a.data[2])
                }
                _ => {
                    return Err(RtError::new(
                        "convert expects an array of 3 coordinates",
                        at.span,
                    ))
                }
            }
        };
        let out = if orient {
            mat_to_euler(&(to.axes.transpose() * from.axes * euler_to_mat(v)))
        } else {
            to.to_local(from.to_object(v))
        };
        Ok(match component {
            Some(c) => Value::Float(match c {
                "x" => out.x,
                "y" => out.y,
                _ => out.z,
            }),
            None => Value::FloatArray(Arc::new(Array::row(vec![out.x, out.y, out.z]))),
        })
    }

    fn frame_of(&self, system: &str, shape: &Shape, at: &RExpr) -> Result<Frame, RtError> {
        Ok(match system {
            "scope" => shape.scope.frame,
            "pivot" => shape.pivot,
            "object" => self.initial.pivot,
            "world" => Frame::IDENTITY,
            other => {
                return Err(RtError::new(
                    format!(
                    "unknown coordinate system `{other}`: expected scope, pivot, object or world"
                ),
                    at.span,
                ))
            }
        })
    }
}

/// A CSV-like table; the delimiter (`,` `;` tab or space) is the one that
/// splits the first line into the most fields.
pub fn parse_table(text: &str) -> Array<Arc<str>> {
    let lines: Vec<&str> = text
        .lines()
        .map(|l| l.trim_end_matches('\r'))
        .filter(|l| !l.trim().is_empty())
        .collect();
    let first = lines.first().copied().unwrap_or("");
    let delimiter = [',', ';', '\t', ' ']
        .into_iter()
        .max_by_key(|&d| first.matches(d).count())
        .unwrap_or(',');
    let rows: Vec<Vec<&str>> = lines
        .iter()
        .map(|l| {
            if delimiter == ' ' {
                l.split_whitespace().collect()
            } else {
                l.split(delimiter).map(|c| c.trim()).collect()
            }
        })
        .collect();
    let cols = rows.iter().map(|r| r.len()).max().unwrap_or(0);
    let mut data = Vec::with_capacity(rows.len() * cols);
    for r in &rows {
        for c in 0..cols {
            data.push(Arc::from(
                r.get(c).map(|s| s.trim_matches('"')).unwrap_or(""),
            ));
        }
    }
    if rows.len() <= 1 {
        return Array::row(data);
    }
    Array {
        rows: rows.len(),
        cols,
        data,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_detects_delimiter_and_pads_rows() {
        let t = parse_table("a;b;c\nd;e\n");
        assert_eq!((t.rows, t.cols), (2, 3));
        assert_eq!(&*t.data[5], "");
        let t = parse_table("1,2\n3,4\n");
        assert_eq!(&*t.data[3], "4");
    }
}
