//! What the language knows besides operations (those are in
//! `cga::operations`): built-in functions with their parameters and a line
//! of ours on each, shape attributes, selector keywords and keywords, for
//! completion, hover, signature help and highlighting.

/// A built-in function: `name(params)` and what it gives.
pub struct Function {
    pub name: &'static str,
    /// The documented argument lists, shortest first.
    pub forms: &'static [&'static [&'static str]],
    pub summary: &'static str,
}

macro_rules! f {
    ($name:literal, [$([$($p:literal),*]),*], $summary:literal) => {
        Function { name: $name, forms: &[$(&[$($p),*]),*], summary: $summary }
    };
}

/// Built-in functions, by family.
pub const FUNCTIONS: &[Function] = &[
    // Math.
    f!("abs", [["x"]], "The absolute value of x."),
    f!("acos", [["x"]], "The arc cosine of x, in degrees."),
    f!("asin", [["x"]], "The arc sine of x, in degrees."),
    f!("atan", [["x"]], "The arc tangent of x, in degrees."),
    f!(
        "atan2",
        [["y", "x"]],
        "The angle of the vector (x, y), in degrees."
    ),
    f!("ceil", [["x"]], "The smallest whole number not below x."),
    f!(
        "clamp",
        [["x", "min", "max"]],
        "x limited to the interval [min, max]."
    ),
    f!("cos", [["angle"]], "The cosine of an angle in degrees."),
    f!("exp", [["x"]], "e to the power x."),
    f!("floor", [["x"]], "The largest whole number not above x."),
    f!("isinf", [["x"]], "Whether x is infinite."),
    f!("isnan", [["x"]], "Whether x is not a number."),
    f!("ln", [["x"]], "The natural logarithm of x."),
    f!("log10", [["x"]], "The base-10 logarithm of x."),
    f!(
        "max",
        [["a", "b"]],
        "The larger of a and b (element-wise for arrays)."
    ),
    f!(
        "min",
        [["a", "b"]],
        "The smaller of a and b (element-wise for arrays)."
    ),
    f!("pow", [["x", "y"]], "x to the power y."),
    f!("rint", [["x"]], "x rounded to the nearest whole number."),
    f!("sin", [["angle"]], "The sine of an angle in degrees."),
    f!("sqrt", [["x"]], "The square root of x."),
    f!("tan", [["angle"]], "The tangent of an angle in degrees."),
    // Random.
    f!(
        "rand",
        [[], ["max"], ["min", "max"]],
        "A random number from the shape's random stream: in [0, 1), [0, max) or [min, max)."
    ),
    f!(
        "p",
        [["probability"]],
        "True with the given probability (0 to 1), drawn from the shape's random stream."
    ),
    // Conversion and text.
    f!(
        "bool",
        [["value"]],
        "The value as a bool (text `true`/`false`, numbers other than 0)."
    ),
    f!(
        "float",
        [["value"]],
        "The value as a float (text is parsed; false is 0, true is 1)."
    ),
    f!(
        "str",
        [["value"]],
        "The value as text, as print() writes it."
    ),
    f!("len", [["text"]], "The number of characters of a text."),
    f!(
        "find",
        [["text", "search", "matchIndex"]],
        "The index of the matchIndex-th occurrence of search in text, or -1."
    ),
    f!(
        "count",
        [["text", "search"]],
        "How often search occurs in text."
    ),
    f!(
        "substring",
        [["text", "start", "end"]],
        "The characters of text from start up to end."
    ),
    f!(
        "replace",
        [["text", "search", "replacement"]],
        "text with every occurrence of search replaced."
    ),
    f!(
        "getPrefix",
        [["text", "delimiter"]],
        "The part of text before the first delimiter."
    ),
    f!(
        "getSuffix",
        [["text", "delimiter"]],
        "The part of text after the last delimiter."
    ),
    f!(
        "getRange",
        [["text", "delimiter", "index"]],
        "The index-th field of text split at delimiter."
    ),
    f!(
        "listAdd",
        [["list", "item"]],
        "A `;`-separated list with item added."
    ),
    f!(
        "listSize",
        [["list"]],
        "The number of items of a `;`-separated list."
    ),
    f!(
        "listItem",
        [["list", "index"]],
        "The item at index of a `;`-separated list."
    ),
    f!(
        "listIndex",
        [["list", "item"]],
        "The index of item in a `;`-separated list, or -1."
    ),
    f!(
        "listRandom",
        [["list"]],
        "A random item of a `;`-separated list."
    ),
    f!(
        "listRange",
        [["list", "start", "end"]],
        "The items start up to end of a `;`-separated list."
    ),
    f!(
        "listClean",
        [["list"]],
        "A `;`-separated list without empty items."
    ),
    // Arrays.
    f!("size", [["array"]], "The number of elements of an array."),
    f!("nRows", [["array"]], "The number of rows of a 2D array."),
    f!(
        "nColumns",
        [["array"]],
        "The number of columns of a 2D array."
    ),
    f!(
        "index",
        [["array", "value"]],
        "The index of the first element equal to value, or -1."
    ),
    f!(
        "sortIndices",
        [["array"]],
        "The indices that sort the array."
    ),
    f!("transpose", [["array"]], "The array's rows as columns."),
    f!(
        "floatArray",
        [[], ["value"]],
        "An empty float array, or value converted to one."
    ),
    f!(
        "boolArray",
        [[], ["value"]],
        "An empty bool array, or value converted to one."
    ),
    f!(
        "stringArray",
        [[], ["value"]],
        "An empty string array, or value converted to one."
    ),
    f!(
        "readFloatTable",
        [["filePath"]],
        "The numbers of a CSV file as a 2D float array."
    ),
    f!(
        "readStringTable",
        [["filePath"]],
        "The fields of a CSV file as a 2D string array."
    ),
    f!("readTextFile", [["filePath"]], "The text of a file."),
    // Files and assets.
    f!(
        "fileExists",
        [["filePath"]],
        "Whether the file exists (searched as the engine searches assets)."
    ),
    f!(
        "fileBasename",
        [["filePath"]],
        "The file's name without folder and extension."
    ),
    f!("fileDirectory", [["filePath"]], "The file's folder."),
    f!(
        "fileExtension",
        [["filePath"]],
        "The file's extension, with its dot."
    ),
    f!(
        "fileName",
        [["filePath"]],
        "The file's name without its folder."
    ),
    f!(
        "fileRandom",
        [["pattern"]],
        "A random file matching a glob pattern."
    ),
    f!(
        "fileSearch",
        [["searchQuery"]],
        "The files matching a search query, as a `;`-separated list."
    ),
    f!(
        "assetInfo",
        [["geometryPath", "infoType"]],
        "A size or position of an asset's bounding box."
    ),
    f!(
        "assetsSortSize",
        [["pattern", "tolerance"]],
        "Assets matching pattern sorted by fit to the scope."
    ),
    f!(
        "assetsSortRatio",
        [["pattern", "axesRatio", "tolerance"]],
        "Assets matching pattern sorted by fit of their proportions."
    ),
    f!(
        "assetNamingInfo",
        [["geometryPath", "infoType"]],
        "A value encoded in an asset's file name."
    ),
    f!(
        "imageInfo",
        [["texturePath", "infoType"]],
        "The width or height of an image."
    ),
    f!(
        "imagesSortRatio",
        [["pattern", "axesRatio", "tolerance"]],
        "Images matching pattern sorted by fit of their proportions."
    ),
    // Output.
    f!(
        "print",
        [["value"]],
        "Writes the value as one line on standard output; gives the value."
    ),
    // Shape queries.
    f!(
        "geometry.area",
        [[], ["selector"]],
        "The area of the shape's faces (those selected)."
    ),
    f!(
        "geometry.volume",
        [[], ["selector"]],
        "The volume enclosed by the shape's geometry."
    ),
    f!("geometry.nFaces", [[]], "The number of faces."),
    f!("geometry.nVertices", [[]], "The number of vertices."),
    f!("geometry.nEdges", [[]], "The number of edges."),
    f!("geometry.nHoles", [[]], "The number of holes."),
    f!(
        "geometry.isClosedSurface",
        [[]],
        "Whether the geometry is a closed surface."
    ),
    f!(
        "geometry.isConcave",
        [[]],
        "Whether a face of the geometry is concave."
    ),
    f!(
        "geometry.isPlanar",
        [["tolerance"]],
        "Whether every face is planar within a tolerance (degrees)."
    ),
    f!(
        "geometry.isOriented",
        [["selector"]],
        "Whether the faces face the selector's direction."
    ),
    f!(
        "geometry.isRectangular",
        [["tolerance"]],
        "Whether the shape is a rectangle within a tolerance (degrees)."
    ),
    f!(
        "geometry.angle",
        [["angleType"]],
        "An angle of the geometry (maxSlope, azimuth, ...)."
    ),
    f!(
        "geometry.boundaryLength",
        [[]],
        "The length of the geometry's boundary."
    ),
    f!(
        "geometry.height",
        [[]],
        "The geometry's extent along the scope's y axis."
    ),
    f!(
        "geometry.du",
        [["uvSet", "surfaceParameterization"]],
        "The width of the UV bounding box."
    ),
    f!(
        "geometry.dv",
        [["uvSet", "surfaceParameterization"]],
        "The height of the UV bounding box."
    ),
    f!(
        "scope.elevation",
        [[]],
        "The scope origin's height in world coordinates."
    ),
    f!(
        "isTagged",
        [["tag"]],
        "Whether a component carries the tag (a comp selector)."
    ),
    f!(
        "getTag",
        [["prefix", "index"]],
        "A tag of the shape with the given prefix."
    ),
    f!(
        "getTags",
        [["prefix"]],
        "The tags of the shape with the given prefix."
    ),
    f!(
        "inside",
        [[], ["target"], ["target", "label"]],
        "Whether the shape lies inside another (context query)."
    ),
    f!(
        "overlaps",
        [[], ["target"], ["target", "label"]],
        "Whether the shape overlaps another (context query)."
    ),
    f!(
        "touches",
        [[], ["target"], ["target", "label"]],
        "Whether the shape touches another (context query)."
    ),
    f!(
        "minimumDistance",
        [["target", "label"]],
        "The smallest distance to other shapes (context query)."
    ),
    f!(
        "contextCompare",
        [["target", "label", "compareType"]],
        "Compares the shape with others (context query)."
    ),
    f!(
        "contextCount",
        [["target", "label"]],
        "The number of other shapes with the label (context query)."
    ),
    f!(
        "convert",
        [[
            "component",
            "fromCoordSystem",
            "toCoordSystem",
            "type",
            "x",
            "y",
            "z"
        ]],
        "A position or orientation converted between coordinate systems."
    ),
    f!(
        "colorHSOToHex",
        [["h", "s", "o"]],
        "A color from hue, saturation and value, as `#rrggbb`."
    ),
    f!(
        "colorRGBToHex",
        [["r", "g", "b"]],
        "A color from red, green and blue (0 to 1), as `#rrggbb`."
    ),
    f!("colorHexToH", [["color"]], "The hue of a `#rrggbb` color."),
    f!(
        "colorHexToS",
        [["color"]],
        "The saturation of a `#rrggbb` color."
    ),
    f!(
        "colorHexToO",
        [["color"]],
        "The value of a `#rrggbb` color."
    ),
    f!(
        "colorHexToR",
        [["color"]],
        "The red part (0 to 1) of a `#rrggbb` color."
    ),
    f!(
        "colorHexToG",
        [["color"]],
        "The green part (0 to 1) of a `#rrggbb` color."
    ),
    f!(
        "colorHexToB",
        [["color"]],
        "The blue part (0 to 1) of a `#rrggbb` color."
    ),
];

/// The built-in function called `name`.
pub fn function(name: &str) -> Option<&'static Function> {
    FUNCTIONS.iter().find(|f| f.name == name)
}

impl Function {
    pub fn signatures(&self) -> Vec<String> {
        self.forms
            .iter()
            .map(|f| format!("{}({})", self.name, f.join(", ")))
            .collect()
    }
}

/// Shape attributes (read as names; `set()` writes some of them).
pub const SHAPE_ATTRIBUTES: &[(&str, &str)] = &[
    ("scope.sx", "The scope's size along its x axis."),
    ("scope.sy", "The scope's size along its y axis."),
    ("scope.sz", "The scope's size along its z axis."),
    ("scope.tx", "The scope's position along the pivot's x axis."),
    ("scope.ty", "The scope's position along the pivot's y axis."),
    ("scope.tz", "The scope's position along the pivot's z axis."),
    ("scope.rx", "The scope's rotation about x, in degrees."),
    ("scope.ry", "The scope's rotation about y, in degrees."),
    ("scope.rz", "The scope's rotation about z, in degrees."),
    (
        "scope.elevation",
        "The scope origin's height in world coordinates.",
    ),
    (
        "split.index",
        "The index of the part in the enclosing split.",
    ),
    ("split.total", "The number of parts of the enclosing split."),
    ("comp.index", "The index of the component in its selection."),
    ("comp.total", "The number of components of its selection."),
    ("comp.sel", "The selector the component was selected with."),
    ("initialShape.name", "The name of the lot."),
    ("initialShape.origin.px", "The initial shape's origin, x."),
    ("initialShape.origin.py", "The initial shape's origin, y."),
    ("initialShape.origin.pz", "The initial shape's origin, z."),
    ("initialShape.startRule", "The start rule of the lot."),
    (
        "material.color.r",
        "The red part of the shape's color (0 to 1).",
    ),
    (
        "material.color.g",
        "The green part of the shape's color (0 to 1).",
    ),
    (
        "material.color.b",
        "The blue part of the shape's color (0 to 1).",
    ),
    ("material.color.rgb", "The shape's color as `#rrggbb`."),
    ("material.opacity", "The shape's opacity (0 to 1)."),
    ("material.name", "The material's name."),
    ("material.colormap", "The texture of the color map."),
    ("material.bumpmap", "The texture of the bump map."),
    ("material.normalmap", "The texture of the normal map."),
    ("material.opacitymap", "The texture of the opacity map."),
    ("material.specularmap", "The texture of the specular map."),
    ("material.roughness", "The material's roughness (0 to 1)."),
    ("material.metallic", "The material's metalness (0 to 1)."),
    ("pivot.px", "The pivot's position, x."),
    ("pivot.py", "The pivot's position, y."),
    ("pivot.pz", "The pivot's position, z."),
    ("pivot.o", "The pivot's orientation."),
    ("seedian", "The seed of the shape's random stream."),
    (
        "trim.horizontal",
        "Whether horizontal trim planes cut inserted assets.",
    ),
    (
        "trim.vertical",
        "Whether vertical trim planes cut inserted assets.",
    ),
    ("nil", "NIL: the empty shape."),
];

/// Selectors of the component split `comp(f) { front : ... }`.
pub const COMP_SELECTORS: &[&str] = &[
    "front",
    "back",
    "left",
    "right",
    "top",
    "bottom",
    "vertical",
    "horizontal",
    "aslant",
    "nutant",
    "side",
    "all",
    "inside",
    "outside",
    "border",
    "eave",
    "hip",
    "valley",
    "ridge",
    "street.front",
    "street.back",
    "street.left",
    "street.right",
    "street.side",
    "object.front",
    "object.back",
    "object.left",
    "object.right",
    "object.top",
    "object.bottom",
    "object.side",
    "world.south",
    "world.north",
    "world.west",
    "world.east",
    "world.up",
    "world.down",
    "world.side",
];

/// The component types of `comp(...)`'s first argument.
pub const COMP_TYPES: &[&str] = &["f", "e", "v", "fe", "fv", "holes", "g"];

/// The axes of `split(...)`'s first argument.
pub const SPLIT_AXES: &[&str] = &["x", "y", "z", "u", "v"];

/// Selectors of `setback`, `offset` and `setbackPerimeter` blocks.
pub const SETBACK_SELECTORS: &[&str] = &[
    "front",
    "back",
    "left",
    "right",
    "all",
    "remainder",
    "inside",
    "border",
    "street.front",
    "street.back",
    "street.left",
    "street.right",
    "street.side",
    "object.front",
    "object.back",
    "object.left",
    "object.right",
    "object.side",
    "isTagged",
];

/// Selector words of other selector arguments (`alignScopeToAxes(y)`,
/// `setPivot(xyz, 0)`, `extrude(world.y, 10)`, `roofShed(15, 1)`, ...).
pub const OTHER_SELECTORS: &[&str] = &[
    "x",
    "y",
    "z",
    "xy",
    "xz",
    "yx",
    "yz",
    "zx",
    "zy",
    "xyz",
    "xzy",
    "yxz",
    "yzx",
    "zxy",
    "zyx",
    "world.x",
    "world.y",
    "world.z",
    "world.up",
    "world.up.flatTop",
    "face.normal",
    "vertex.normal",
    "vertex.normal.withoutMerging",
    "keepSizeAndPosition",
    "keepSizeAlignPosition",
    "fromOrigin",
    "scopeCenter",
    "xyzPlane",
    "relative",
    "absolute",
    "noAdjust",
    "adjust",
    "keepLarger",
    "keepSmaller",
    "keepOriginal",
    "keepLast",
    "first",
    "last",
    "uniform",
    "gaussian",
    "surface",
    "volume",
    "edges",
];

/// Whether `word` is a selector keyword of some operation.
pub fn is_selector(word: &str) -> bool {
    [
        COMP_SELECTORS,
        COMP_TYPES,
        SPLIT_AXES,
        SETBACK_SELECTORS,
        OTHER_SELECTORS,
    ]
    .iter()
    .any(|list| list.contains(&word))
}

/// Keywords of the language.
pub const KEYWORDS: &[&str] = &[
    "attr",
    "const",
    "import",
    "style",
    "extends",
    "case",
    "else",
    "with",
    "version",
    "start",
    "extension",
    "NIL",
    "true",
    "false",
    "float",
    "bool",
    "string",
    "float[]",
    "bool[]",
    "string[]",
];

#[cfg(test)]
mod tests {
    /// The VS Code grammar (`editors/vscode/syntaxes/cga.tmLanguage.json`)
    /// names every operation of the engine's table and every built-in
    /// function here, so that highlighting follows the table.
    #[test]
    fn the_vscode_grammar_names_every_operation_and_function() {
        let path = cga_testkit::repo_root().join("editors/vscode/syntaxes/cga.tmLanguage.json");
        let grammar: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let words = |key: &str| -> Vec<String> {
            let m = grammar["repository"][key]["match"].as_str().unwrap();
            let inner = m.split_once("(?:").unwrap().1;
            let inner = inner.split_once(')').unwrap().0;
            inner
                .split('|')
                .map(|w| w.replace("\\\\.", ".").replace("\\.", "."))
                .collect()
        };
        let ops = words("operations");
        let mut names: Vec<&str> = cga::operations::all()
            .iter()
            .flat_map(|o| std::iter::once(o.name).chain(o.aliases.iter().copied()))
            .collect();
        names.sort();
        names.dedup();
        let missing: Vec<&&str> = names
            .iter()
            .filter(|n| !ops.iter().any(|o| o == *n))
            .collect();
        assert!(
            missing.is_empty(),
            "operations missing from the grammar: {missing:?}\nall: {}",
            names.join("|")
        );
        let functions = words("functions");
        let missing: Vec<&str> = super::FUNCTIONS
            .iter()
            .map(|f| f.name)
            .filter(|n| !n.contains('.') && !functions.iter().any(|o| o == n))
            .collect();
        assert!(
            missing.is_empty(),
            "functions missing from the grammar: {missing:?}"
        );
    }
}
