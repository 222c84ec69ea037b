//! The table of CGA's operations: every name the language knows as an
//! operation, with its documented argument lists (parameter names, and
//! which arguments are selector keywords), its block, its family and a
//! one-line description. The resolver checks calls against it and reads
//! the argument modes from it; the interpreter dispatches on the [`Op`] it
//! gives; editors take completion, hover and signature help from it.

use super::{
    AttrOp, CleanupOp, CreateOp, FootprintOp, Op, Primitive, RoofOp, ScopeOp, SetTarget, TagOp,
    TextureOp, TransformOp,
};
use cga_geometry::boolean::BoolOp;

/// How the resolver reads an argument: an expression, a selector keyword
/// (`x`, `world.up`, `scopeCenter`, ...), or either (a name there is a
/// selector if it is a known selector word, else an expression).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArgMode {
    Expr,
    Selector,
    Maybe,
}

/// One parameter of an argument list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Param {
    pub name: &'static str,
    pub mode: ArgMode,
}

const fn e(name: &'static str) -> Param {
    Param {
        name,
        mode: ArgMode::Expr,
    }
}

const fn s(name: &'static str) -> Param {
    Param {
        name,
        mode: ArgMode::Selector,
    }
}

const fn m(name: &'static str) -> Param {
    Param {
        name,
        mode: ArgMode::Maybe,
    }
}

/// What follows an operation's arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    /// Nothing.
    None,
    /// Parts: `{ head : operations | ... }` (split, comp, setback, ...).
    Parts,
    /// Operations: `{ operations }` (inline, scatter, the Boolean operands).
    Operations,
}

/// The groups of operations of the reference's index.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Family {
    Subdivision,
    Creation,
    Transformation,
    Scope,
    Texturing,
    Roofs,
    Footprint,
    GeometryCleanup,
    Structure,
    Boolean,
    Tags,
    Context,
    AttributesAndOutput,
}

impl Family {
    pub fn name(self) -> &'static str {
        match self {
            Family::Subdivision => "subdivision",
            Family::Creation => "geometry creation",
            Family::Transformation => "transformation",
            Family::Scope => "scope and pivot",
            Family::Texturing => "texturing",
            Family::Roofs => "roofs",
            Family::Footprint => "footprint",
            Family::GeometryCleanup => "geometry clean-up",
            Family::Structure => "rule structure",
            Family::Boolean => "Boolean",
            Family::Tags => "component tags",
            Family::Context => "context",
            Family::AttributesAndOutput => "attributes and output",
        }
    }
}

/// What the engine does with a call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Run {
    /// Runs it.
    Op(Op),
    /// Reads it itself while resolving (`set`, `inline`): not dispatched
    /// through [`Op`] from the table.
    Resolver,
    /// Does not run it: it was deprecated (the reason, for the warning).
    Deprecated(&'static str),
    /// Does not run it yet (a warning; the shape is left unchanged).
    Unsupported,
}

/// One operation.
#[derive(Clone, Copy, Debug)]
pub struct OpDef {
    pub name: &'static str,
    /// Other names of the same operation (`insert` for `i`, `offsetUV`,
    /// translateUV's name before 2009.3).
    pub aliases: &'static [&'static str],
    pub run: Run,
    pub family: Family,
    /// The documented argument lists, shortest first.
    pub forms: &'static [&'static [Param]],
    /// Argument counts accepted, inclusive (the forms' counts, and those
    /// between them that the engine reads too).
    pub arity: (usize, usize),
    pub block: Block,
    /// What it does, in a line.
    pub summary: &'static str,
}

/// Whether the engine runs an operation, as a user reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    Runs,
    /// Deprecated and not run (the reason).
    Deprecated(&'static str),
    /// Not run yet: a warning, the shape unchanged.
    NotRun,
}

impl OpDef {
    pub fn status(&self) -> Status {
        match self.run {
            Run::Op(_) | Run::Resolver => Status::Runs,
            Run::Deprecated(why) => Status::Deprecated(why),
            Run::Unsupported => Status::NotRun,
        }
    }

    /// Whether a call with `n` arguments is accepted.
    pub fn accepts(&self, n: usize) -> bool {
        (self.arity.0..=self.arity.1).contains(&n)
    }

    /// How argument `pos` of a call with `n` arguments is read: by the
    /// form of `n` parameters, else by the longest form that has one at
    /// `pos`; operations without documented forms read names as selector
    /// words where they are ones.
    pub fn mode(&self, n: usize, pos: usize) -> ArgMode {
        let form = self
            .forms
            .iter()
            .find(|f| f.len() == n)
            .or_else(|| self.forms.iter().rev().find(|f| f.len() > pos));
        match form.and_then(|f| f.get(pos)) {
            Some(p) => p.mode,
            None if self.forms.is_empty() => ArgMode::Maybe,
            None => ArgMode::Expr,
        }
    }

    /// The forms as written in the reference: `extrude(extrusionType,
    /// distance)`.
    pub fn signatures(&self) -> Vec<String> {
        self.forms
            .iter()
            .map(|f| {
                let params: Vec<&str> = f.iter().map(|p| p.name).collect();
                format!("{}({})", self.name, params.join(", "))
            })
            .collect()
    }

    /// The argument counts accepted, as text for messages ("1 or 2", "3 to
    /// 10", "no").
    pub fn arity_text(&self) -> String {
        match self.arity {
            (0, 0) => "no".to_string(),
            (a, b) if a == b => a.to_string(),
            (a, b) if b == a + 1 => format!("{a} or {b}"),
            (a, b) => format!("{a} to {b}"),
        }
    }
}

/// The operation called `name` (or one of its other names).
pub fn find(name: &str) -> Option<&'static OpDef> {
    OPERATIONS
        .iter()
        .find(|d| d.name == name || d.aliases.contains(&name))
}

/// Every name of an operation, for suggestions.
pub fn names() -> impl Iterator<Item = &'static str> {
    OPERATIONS
        .iter()
        .flat_map(|d| std::iter::once(d.name).chain(d.aliases.iter().copied()))
}

/// The name of the operation `op` runs as (its table entry's).
pub fn name_of(op: Op) -> &'static str {
    match op {
        Op::Attr(AttrOp::Set(_)) => "set",
        Op::Inline => "inline",
        _ => OPERATIONS
            .iter()
            .find(|d| same_op(d.run, op))
            .map_or("operation", |d| d.name),
    }
}

fn same_op(run: Run, op: Op) -> bool {
    matches!(run, Run::Op(o) if o == op)
}

const DEPRECATED_2009_3: &str = "was deprecated in CGA 2009.3 and is not run";

const fn def(
    name: &'static str,
    run: Run,
    family: Family,
    forms: &'static [&'static [Param]],
    block: Block,
    summary: &'static str,
) -> OpDef {
    let mut min = usize::MAX;
    let mut max = 0;
    let mut i = 0;
    while i < forms.len() {
        let n = forms[i].len();
        if n < min {
            min = n;
        }
        if n > max {
            max = n;
        }
        i += 1;
    }
    if forms.is_empty() {
        min = 0;
        max = usize::MAX;
    }
    OpDef {
        name,
        aliases: &[],
        run,
        family,
        forms,
        arity: (min, max),
        block,
        summary,
    }
}

const fn with_aliases(d: OpDef, aliases: &'static [&'static str]) -> OpDef {
    OpDef { aliases, ..d }
}

use Block::{None as NoBlock, Operations, Parts};
use Family::*;

/// Every operation, in the order of the reference's index.
pub static OPERATIONS: &[OpDef] = &[
    // Subdivision.
    def(
        "split",
        Run::Op(Op::Split),
        Subdivision,
        &[
            &[s("axis")],
            &[s("axis"), s("adjustMode")],
            &[s("direction"), s("surfaceParameterization"), e("uvSet")],
        ],
        Parts,
        "Cuts the shape along an axis (or in uv space) into parts of absolute, relative (') and floating (~) sizes, repeated with { }*.",
    ),
    def(
        "splitArea",
        Run::Op(Op::SplitArea),
        Subdivision,
        &[&[s("axis")], &[s("axis"), s("adjustMode")]],
        Parts,
        "Cuts planar geometry along an axis into parts of the given areas.",
    ),
    def(
        "comp",
        Run::Op(Op::Comp),
        Subdivision,
        &[&[s("component")], &[s("component"), s("scopeAlignment")]],
        Parts,
        "Breaks the shape into its faces, edges, vertices, groups, materials or holes, selected by index or selector, one shape each (:) or together (=).",
    ),
    def(
        "splitAndSetbackPerimeter",
        Run::Op(Op::Footprint(FootprintOp::SplitAndSetbackPerimeter)),
        Subdivision,
        &[
            &[e("splitOffset")],
            &[e("splitOffset"), e("firstEdgeIndex"), e("selectedEdgesMask")],
        ],
        Parts,
        "Splits the perimeter into lengths and sets each back by its own depth; the rest is the remainder.",
    ),
    def(
        "modify",
        Run::Op(Op::Modify),
        Subdivision,
        &[&[s("component")], &[s("component"), s("scopeAlignment")]],
        Parts,
        "Edits selected components of the geometry in place, keeping it one shape.",
    ),
    def(
        "scatter",
        Run::Op(Op::Scatter),
        Subdivision,
        &[
            &[m("domain"), m("nPoints"), m("distributionType")],
            &[
                m("domain"),
                m("nPoints"),
                m("gaussian"),
                m("scatterMean"),
                m("scatterStddev"),
            ],
        ],
        Operations,
        "Places point shapes at random in or on the geometry.",
    ),
    // Geometry creation.
    def(
        "extrude",
        Run::Op(Op::Create(CreateOp::Extrude)),
        Creation,
        &[&[e("distance")], &[s("extrusionType"), e("distance")]],
        NoBlock,
        "Extrudes every face along its normal (or world.up, or vertex normals) into a closed volume.",
    ),
    with_aliases(
        def(
            "i",
            Run::Op(Op::Create(CreateOp::Insert)),
            Creation,
            &[
                &[e("filePath")],
                &[e("filePath"), s("upAxisOfGeometry")],
                &[e("filePath"), s("upAxisOfGeometry"), s("insertMode")],
                &[e("filePath"), s("upAxisOfGeometry"), s("insertMode"), s("cleanupMode")],
            ],
            NoBlock,
            "Inserts a geometry asset (OBJ, COLLADA, glTF) fitted into the scope.",
        ),
        &["insert"],
    ),
    def(
        "primitiveQuad",
        Run::Op(Op::Create(CreateOp::Primitive(Primitive::Quad))),
        Creation,
        &[&[], &[e("width"), e("length")]],
        NoBlock,
        "Replaces the geometry by a quad filling the scope.",
    ),
    def(
        "primitiveDisk",
        Run::Op(Op::Create(CreateOp::Primitive(Primitive::Disk))),
        Creation,
        &[&[], &[e("nVertices")], &[e("nVertices"), e("radius")]],
        NoBlock,
        "Replaces the geometry by a disk filling the scope.",
    ),
    def(
        "primitiveCube",
        Run::Op(Op::Create(CreateOp::Primitive(Primitive::Cube))),
        Creation,
        &[&[], &[e("width"), e("height"), e("depth")]],
        NoBlock,
        "Replaces the geometry by a box filling the scope.",
    ),
    def(
        "primitiveSphere",
        Run::Op(Op::Create(CreateOp::Primitive(Primitive::Sphere))),
        Creation,
        &[
            &[],
            &[e("sides"), e("divisions")],
            &[e("sides"), e("divisions"), e("radius")],
        ],
        NoBlock,
        "Replaces the geometry by a sphere filling the scope.",
    ),
    def(
        "primitiveCylinder",
        Run::Op(Op::Create(CreateOp::Primitive(Primitive::Cylinder))),
        Creation,
        &[&[], &[e("sides")], &[e("sides"), e("radius"), e("height")]],
        NoBlock,
        "Replaces the geometry by a cylinder filling the scope.",
    ),
    def(
        "primitiveCone",
        Run::Op(Op::Create(CreateOp::Primitive(Primitive::Cone))),
        Creation,
        &[&[], &[e("sides")], &[e("sides"), e("radius"), e("height")]],
        NoBlock,
        "Replaces the geometry by a cone filling the scope.",
    ),
    def(
        "insertAlongUV",
        Run::Op(Op::Texturing(TextureOp::InsertAlongUV)),
        Creation,
        &[
            &[m("uvSet"), m("filePath"), m("height")],
            &[
                m("uvSet"),
                m("filePath"),
                m("height"),
                m("heightDirection"),
                m("heightAlignment"),
            ],
        ],
        NoBlock,
        "Bends an asset along the texture coordinates of the geometry (a street's lanes, a fence along an edge).",
    ),
    // Transformations.
    def(
        "t",
        Run::Op(Op::Transform(TransformOp::T)),
        Transformation,
        &[&[e("tx"), e("ty"), e("tz")]],
        NoBlock,
        "Moves the scope along its own axes.",
    ),
    def(
        "translate",
        Run::Op(Op::Transform(TransformOp::Translate)),
        Transformation,
        &[&[s("mode"), s("coordSystem"), e("x"), e("y"), e("z")]],
        NoBlock,
        "Moves the scope in a chosen coordinate system, relatively or to absolute coordinates.",
    ),
    def(
        "s",
        Run::Op(Op::Transform(TransformOp::S)),
        Transformation,
        &[&[e("xSize"), e("ySize"), e("zSize")]],
        NoBlock,
        "Sets the scope's size (the geometry is scaled with it).",
    ),
    def(
        "r",
        Run::Op(Op::Transform(TransformOp::R)),
        Transformation,
        &[
            &[e("xAngle"), e("yAngle"), e("zAngle")],
            &[s("center"), e("xAngle"), e("yAngle"), e("zAngle")],
        ],
        NoBlock,
        "Rotates the scope about the pivot's axes (in degrees, x then y then z), about its origin or centre.",
    ),
    def(
        "rotate",
        Run::Op(Op::Transform(TransformOp::Rotate)),
        Transformation,
        &[&[s("mode"), s("coordSystem"), e("xAngle"), e("yAngle"), e("zAngle")]],
        NoBlock,
        "Rotates the scope in a chosen coordinate system, relatively or to absolute angles.",
    ),
    def(
        "center",
        Run::Op(Op::Transform(TransformOp::Center)),
        Transformation,
        &[&[s("axes")]],
        NoBlock,
        "Centres the scope in the scope of the shape before it, along the chosen axes.",
    ),
    def(
        "mirror",
        Run::Op(Op::Cleanup(CleanupOp::Mirror)),
        Transformation,
        &[&[m("xFlip"), m("yFlip"), m("zFlip")]],
        NoBlock,
        "Mirrors the geometry within the scope along the chosen axes.",
    ),
    // Scope and pivot.
    def(
        "alignScopeToAxes",
        Run::Op(Op::Scope(ScopeOp::AlignScopeToAxes)),
        Scope,
        &[&[], &[s("alignAxes")]],
        NoBlock,
        "Turns the scope parallel to the world (or object) axes.",
    ),
    def(
        "alignScopeToGeometry",
        Run::Op(Op::Scope(ScopeOp::AlignScopeToGeometry)),
        Scope,
        &[
            &[s("upAxis"), m("faceIndex")],
            &[s("upAxis"), m("faceIndex"), m("edgeIndex")],
        ],
        NoBlock,
        "Turns the scope to a face and one of its edges of the geometry.",
    ),
    def(
        "alignScopeToGeometryBBox",
        Run::Op(Op::AlignScopeToGeometryBBox),
        Scope,
        &[&[s("alignAxes")]],
        NoBlock,
        "Turns the scope to the geometry's smallest bounding box.",
    ),
    def(
        "setPivot",
        Run::Op(Op::Scope(ScopeOp::SetPivot)),
        Scope,
        &[&[s("axisMap"), e("cornerIndex")]],
        NoBlock,
        "Moves and turns the pivot to a corner of the scope.",
    ),
    def(
        "rotateScope",
        Run::Op(Op::Scope(ScopeOp::RotateScope)),
        Scope,
        &[&[e("xAngle"), e("yAngle"), e("zAngle")]],
        NoBlock,
        "Rotates the scope, not the geometry, and fits it to the geometry again.",
    ),
    def(
        "mirrorScope",
        Run::Op(Op::Scope(ScopeOp::MirrorScope)),
        Scope,
        &[&[e("xFlip"), e("yFlip"), e("zFlip")]],
        NoBlock,
        "Mirrors the scope, not the geometry.",
    ),
    def(
        "resetGeometry",
        Run::Op(Op::Scope(ScopeOp::ResetGeometry)),
        Scope,
        &[&[]],
        NoBlock,
        "Sets the geometry, scope and pivot back to the initial shape's.",
    ),
    // Texturing.
    def(
        "setupProjection",
        Run::Op(Op::Texturing(TextureOp::SetupProjection)),
        Texturing,
        &[
            &[e("uvSet"), s("axes"), e("textureWidth"), e("textureHeight")],
            &[
                e("uvSet"),
                s("axes"),
                e("textureWidth"),
                e("textureHeight"),
                e("widthOffset"),
                e("heightOffset"),
            ],
            &[
                e("uvSet"),
                s("axes"),
                e("textureWidth"),
                e("textureHeight"),
                e("widthOffset"),
                e("heightOffset"),
                e("uwFactor"),
            ],
        ],
        NoBlock,
        "Sets up a planar texture projection of a uv set in scope or world coordinates.",
    ),
    def(
        "projectUV",
        Run::Op(Op::Texturing(TextureOp::ProjectUV)),
        Texturing,
        &[&[e("uvSet")]],
        NoBlock,
        "Applies a uv set's projection: writes its texture coordinates.",
    ),
    with_aliases(
        def(
            "translateUV",
            Run::Op(Op::Texturing(TextureOp::TranslateUV)),
            Texturing,
            &[&[e("uvSet"), e("uOffset"), e("vOffset")]],
            NoBlock,
            "Adds offsets to a uv set's texture coordinates.",
        ),
        &["offsetUV"],
    ),
    def(
        "scaleUV",
        Run::Op(Op::Texturing(TextureOp::ScaleUV)),
        Texturing,
        &[&[e("uvSet"), e("uFactor"), e("vFactor")]],
        NoBlock,
        "Multiplies a uv set's texture coordinates.",
    ),
    def(
        "rotateUV",
        Run::Op(Op::Texturing(TextureOp::RotateUV)),
        Texturing,
        &[&[e("uvSet"), e("angle")]],
        NoBlock,
        "Rotates a uv set's texture coordinates (degrees).",
    ),
    def(
        "normalizeUV",
        Run::Op(Op::Texturing(TextureOp::NormalizeUV)),
        Texturing,
        &[&[e("uvSet"), s("normalizeMode"), s("normalizeType")]],
        NoBlock,
        "Fits a uv set's texture coordinates into [0, 1].",
    ),
    def(
        "tileUV",
        Run::Op(Op::Texturing(TextureOp::TileUV)),
        Texturing,
        &[&[e("uvSet"), e("textureWidth"), e("textureHeight")]],
        NoBlock,
        "Rescales a uv set so that the texture repeats at the given size in metres.",
    ),
    def(
        "deleteUV",
        Run::Op(Op::Texturing(TextureOp::DeleteUV)),
        Texturing,
        &[&[e("uvSet")]],
        NoBlock,
        "Removes a uv set's texture coordinates.",
    ),
    def(
        "copyUV",
        Run::Op(Op::Texturing(TextureOp::CopyUV)),
        Texturing,
        &[&[e("uvSetSource"), e("uvSetDest")]],
        NoBlock,
        "Copies the texture coordinates of one uv set to another.",
    ),
    def(
        "texture",
        Run::Op(Op::Texturing(TextureOp::Texture)),
        Texturing,
        &[&[e("filePath")]],
        NoBlock,
        "Sets the colour map (and, for images with alpha, the opacity map) of the material.",
    ),
    def(
        "setupUV",
        Run::Deprecated(DEPRECATED_2009_3),
        Texturing,
        &[],
        NoBlock,
        "Deprecated (2009.3): use setupProjection.",
    ),
    def(
        "bakeUV",
        Run::Deprecated(DEPRECATED_2009_3),
        Texturing,
        &[],
        NoBlock,
        "Deprecated (2009.3): use projectUV.",
    ),
    // Roofs.
    def(
        "roofGable",
        Run::Op(Op::Roof(RoofOp::Gable)),
        Roofs,
        &[
            &[m("angle")],
            &[m("angle"), e("overhangX")],
            &[m("angle"), e("overhangX"), e("overhangY")],
            &[m("angle"), e("overhangX"), e("overhangY"), e("even")],
            &[m("angle"), e("overhangX"), e("overhangY"), e("even"), e("index")],
        ],
        NoBlock,
        "Builds a gable roof over each face, at an angle or to a height (byAngle, byHeight).",
    ),
    def(
        "roofHip",
        Run::Op(Op::Roof(RoofOp::Hip)),
        Roofs,
        &[
            &[m("angle")],
            &[m("angle"), e("overhang")],
            &[m("angle"), e("overhang"), e("even")],
            &[m("valueType"), e("value"), e("overhang"), e("even")],
        ],
        NoBlock,
        "Builds a hip roof over each face: every edge rises at the angle.",
    ),
    def(
        "roofPyramid",
        Run::Op(Op::Roof(RoofOp::Pyramid)),
        Roofs,
        &[&[m("angle")], &[m("valueType"), e("value")]],
        NoBlock,
        "Builds a pyramid over each face, its apex above the face's centre.",
    ),
    def(
        "roofShed",
        Run::Op(Op::Roof(RoofOp::Shed)),
        Roofs,
        &[
            &[m("angle")],
            &[m("angle"), e("index")],
            &[m("valueType"), e("value"), e("index")],
        ],
        NoBlock,
        "Builds a shed roof over each face, rising from one edge.",
    ),
    def(
        "roofRidge",
        Run::Op(Op::Roof(RoofOp::Ridge)),
        Roofs,
        &[&[m("angle")], &[m("valueType"), e("value")]],
        NoBlock,
        "Builds a roof whose ridges follow the face's medial axis at a height.",
    ),
    def(
        "roof",
        Run::Deprecated(DEPRECATED_2009_3),
        Roofs,
        &[],
        NoBlock,
        "Deprecated (2009.3): use roofGable, roofHip, roofPyramid or roofShed.",
    ),
    // Footprint.
    def(
        "offset",
        Run::Op(Op::Footprint(FootprintOp::Offset)),
        Footprint,
        &[&[e("distance")], &[e("distance"), s("keepFaces")]],
        NoBlock,
        "Offsets every face's outline inwards (negative) or outwards, keeping the inside, the border or both.",
    ),
    def(
        "setback",
        Run::Op(Op::Footprint(FootprintOp::Setback)),
        Footprint,
        &[&[m("distance")], &[m("distance"), m("uvSet")]],
        Parts,
        "Sets selected edges back by a distance: the strips along them and the remainder become shapes.",
    ),
    def(
        "setbackPerEdge",
        Run::Op(Op::Footprint(FootprintOp::SetbackPerEdge)),
        Footprint,
        &[&[m("distance")], &[m("distance"), m("uvSet")]],
        Parts,
        "Like setback, with the distance evaluated for each edge.",
    ),
    def(
        "setbackToArea",
        Run::Op(Op::Footprint(FootprintOp::SetbackToArea)),
        Footprint,
        &[
            &[m("area")],
            &[m("area"), m("minDistances")],
            &[m("area"), m("minDistances"), m("maxDistances")],
            &[m("area"), m("minDistances"), m("maxDistances"), m("uvSet")],
        ],
        Parts,
        "Sets edges back so that the remainder has the given area.",
    ),
    def(
        "shapeL",
        Run::Op(Op::Footprint(FootprintOp::ShapeL)),
        Footprint,
        &[&[m("frontWidth"), m("leftWidth")]],
        Parts,
        "Makes an L of the front and left edges' strips; the rest is the remainder.",
    ),
    def(
        "shapeU",
        Run::Op(Op::Footprint(FootprintOp::ShapeU)),
        Footprint,
        &[&[m("frontWidth"), m("rightWidth"), m("leftWidth")]],
        Parts,
        "Makes a U of the front, right and left edges' strips; the rest is the remainder.",
    ),
    def(
        "shapeO",
        Run::Op(Op::Footprint(FootprintOp::ShapeO)),
        Footprint,
        &[&[m("frontWidth"), m("rightWidth"), m("backWidth"), m("leftWidth")]],
        Parts,
        "Makes a ring of strips along all edges; the inside is the remainder.",
    ),
    def(
        "innerRectangle",
        Run::Op(Op::Footprint(FootprintOp::InnerRectangle)),
        Footprint,
        &[&[m("alignment")]],
        Parts,
        "Finds the largest rectangle inside each face: it and the rest become shapes.",
    ),
    def(
        "innerRect",
        Run::Op(Op::Footprint(FootprintOp::InnerRect)),
        Footprint,
        &[&[]],
        NoBlock,
        "Deprecated (2016.0): the largest rectangle inside the face; use innerRectangle.",
    ),
    def(
        "envelope",
        Run::Op(Op::Footprint(FootprintOp::Envelope)),
        Footprint,
        &[
            &[m("maxHeight"), e("baseHeight"), e("angle")],
            &[m("direction"), e("maxHeight"), e("frontBaseHeight"), e("frontAngle")],
            &[
                m("direction"),
                e("maxHeight"),
                e("frontBaseHeight"),
                e("frontAngle"),
                e("backBaseHeight"),
                e("backAngle"),
            ],
            &[
                m("direction"),
                e("maxHeight"),
                e("frontBaseHeight"),
                e("frontAngle"),
                e("backBaseHeight"),
                e("backAngle"),
                e("sideBaseHeight"),
                e("sideAngle"),
            ],
            &[
                m("direction"),
                e("maxHeight"),
                e("frontBaseHeight"),
                e("frontAngle"),
                e("backBaseHeight"),
                e("backAngle"),
                e("rightBaseHeight"),
                e("rightAngle"),
                e("leftBaseHeight"),
                e("leftAngle"),
            ],
        ],
        NoBlock,
        "Builds the volume a zoning envelope allows above each face: walls up to base heights, then planes at angles, capped at a height.",
    ),
    def(
        "taper",
        Run::Op(Op::Footprint(FootprintOp::Taper)),
        Footprint,
        &[&[m("height")]],
        NoBlock,
        "Makes a pyramid of the first face, its apex at a height above the centre.",
    ),
    def(
        "footprint",
        Run::Op(Op::Footprint(FootprintOp::Footprint)),
        Footprint,
        &[&[]],
        NoBlock,
        "Replaces the geometry by its outline projected onto the scope's x-z plane.",
    ),
    // Geometry clean-up.
    def(
        "convexify",
        Run::Op(Op::Cleanup(CleanupOp::Convexify)),
        GeometryCleanup,
        &[&[], &[m("maxLength")]],
        NoBlock,
        "Splits concave faces into convex ones.",
    ),
    def(
        "deleteHoles",
        Run::Op(Op::Cleanup(CleanupOp::DeleteHoles)),
        GeometryCleanup,
        &[&[]],
        NoBlock,
        "Removes the holes of the faces.",
    ),
    def(
        "reverseNormals",
        Run::Op(Op::Cleanup(CleanupOp::ReverseNormals)),
        GeometryCleanup,
        &[&[]],
        NoBlock,
        "Turns every face around.",
    ),
    def(
        "cleanupGeometry",
        Run::Op(Op::Cleanup(CleanupOp::CleanupGeometry)),
        GeometryCleanup,
        &[&[m("components"), m("tolerance")]],
        NoBlock,
        "Merges close vertices, removes degenerate faces and merges coplanar ones.",
    ),
    def(
        "setNormals",
        Run::Op(Op::Cleanup(CleanupOp::SetNormals)),
        GeometryCleanup,
        &[&[m("normalsMode")]],
        NoBlock,
        "Sets the vertex normals hard, soft or by the given mode.",
    ),
    def(
        "softenNormals",
        Run::Op(Op::Cleanup(CleanupOp::SoftenNormals)),
        GeometryCleanup,
        &[&[e("angle")]],
        NoBlock,
        "Smooths the normals across edges whose faces meet below an angle.",
    ),
    def(
        "reduceGeometry",
        Run::Op(Op::Cleanup(CleanupOp::ReduceGeometry)),
        GeometryCleanup,
        &[&[m("tolerance")]],
        NoBlock,
        "Simplifies the geometry by collapsing short edges.",
    ),
    def(
        "rectify",
        Run::Op(Op::Cleanup(CleanupOp::Rectify)),
        GeometryCleanup,
        &[&[m("angle")]],
        NoBlock,
        "Straightens nearly parallel or perpendicular edges.",
    ),
    def(
        "trim",
        Run::Op(Op::Trim),
        GeometryCleanup,
        &[&[]],
        NoBlock,
        "Cuts the geometry with the shape's trim planes.",
    ),
    // Rule structure.
    def(
        "inline",
        Run::Resolver,
        Structure,
        &[&[], &[s("geometryMergeStrategy")]],
        Operations,
        "Derives a rule or operations at once and merges the resulting shapes into the current one.",
    ),
    def(
        "label",
        Run::Op(Op::Label),
        Context,
        &[&[e("label")]],
        NoBlock,
        "Names the shape for context queries (occlusion, minimumDistance, contextCount).",
    ),
    // Boolean.
    def(
        "union",
        Run::Op(Op::Boolean(BoolOp::Union)),
        Boolean,
        &[&[]],
        Operations,
        "Unites the volumes of the operands' results.",
    ),
    def(
        "subtract",
        Run::Op(Op::Boolean(BoolOp::Subtract)),
        Boolean,
        &[&[]],
        Operations,
        "Removes the second operand's volume from the first's.",
    ),
    def(
        "intersect",
        Run::Op(Op::Boolean(BoolOp::Intersect)),
        Boolean,
        &[&[]],
        Operations,
        "Keeps the volume the operands' results share.",
    ),
    // Component tags.
    def(
        "tag",
        Run::Op(Op::Tags(TagOp::Tag)),
        Tags,
        &[&[e("name")], &[e("name"), s("components")]],
        NoBlock,
        "Tags the geometry's faces (or edges or vertices) with a name.",
    ),
    def(
        "deleteTags",
        Run::Op(Op::Tags(TagOp::DeleteTags)),
        Tags,
        &[&[], &[e("tagQuery")], &[e("tagQuery"), s("components")]],
        NoBlock,
        "Removes tags (those matching a query) from the geometry.",
    ),
    def(
        "setTagsFromEdgeAttrs",
        Run::Unsupported,
        Tags,
        &[&[]],
        NoBlock,
        "Turns the initial shape's string edge attributes into edge tags.",
    ),
    // Attributes and output.
    def(
        "set",
        Run::Resolver,
        AttributesAndOutput,
        &[&[e("attribute"), e("value")]],
        NoBlock,
        "Sets an attribute (or a shape attribute such as material.color) of the shape.",
    ),
    def(
        "color",
        Run::Op(Op::Attr(AttrOp::Color)),
        AttributesAndOutput,
        &[
            &[e("hexValue")],
            &[e("red"), e("green"), e("blue")],
            &[e("red"), e("green"), e("blue"), e("opacity")],
        ],
        NoBlock,
        "Sets the material's colour (\"#rrggbb\", or red, green, blue and opacity in [0, 1]).",
    ),
    def(
        "setMaterial",
        Run::Op(Op::Attr(AttrOp::SetMaterial)),
        AttributesAndOutput,
        &[&[e("material")]],
        NoBlock,
        "Sets every material attribute from a material (getMaterial, readMaterial).",
    ),
    def(
        "resetMaterial",
        Run::Op(Op::Attr(AttrOp::ResetMaterial)),
        AttributesAndOutput,
        &[&[], &[s("target")]],
        NoBlock,
        "Sets the material back to CGA's default.",
    ),
    def(
        "print",
        Run::Op(Op::Attr(AttrOp::Print)),
        AttributesAndOutput,
        &[&[e("value")]],
        NoBlock,
        "Writes a value on a line of its own (standard output).",
    ),
    def(
        "report",
        Run::Op(Op::Attr(AttrOp::Report)),
        AttributesAndOutput,
        &[&[e("key"), e("value")]],
        NoBlock,
        "Adds a value to a report key; the reports of all shapes are totalled.",
    ),
];

/// The `set` operation's [`Op`] for a target (the resolver makes it).
pub fn set_op(target: SetTarget) -> Op {
    Op::Attr(AttrOp::Set(target))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_forms_give_the_arity() {
        let mut names: Vec<&str> = names().collect();
        let n = names.len();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), n, "a name twice in the table");
        let extrude = find("extrude").unwrap();
        assert_eq!(extrude.arity, (1, 2));
        assert_eq!(extrude.mode(2, 0), ArgMode::Selector);
        assert_eq!(extrude.mode(1, 0), ArgMode::Expr);
        assert_eq!(
            extrude.signatures(),
            vec!["extrude(distance)", "extrude(extrusionType, distance)"]
        );
        let split = find("split").unwrap();
        assert_eq!(split.mode(3, 2), ArgMode::Expr);
        assert_eq!(split.mode(3, 0), ArgMode::Selector);
        assert_eq!(find("insert").unwrap().name, "i");
        assert_eq!(find("offsetUV").unwrap().name, "translateUV");
        assert_eq!(find("envelope").unwrap().arity, (3, 10));
        assert_eq!(find("envelope").unwrap().arity_text(), "3 to 10");
        assert_eq!(find("roof").unwrap().mode(2, 1), ArgMode::Maybe);
        assert!(find("nope").is_none());
        assert!(OPERATIONS.iter().all(|d| !d.summary.is_empty()));
    }

    #[test]
    fn every_op_has_its_name() {
        assert_eq!(name_of(Op::Create(CreateOp::Insert)), "i");
        assert_eq!(name_of(Op::Roof(RoofOp::Gable)), "roofGable");
        assert_eq!(name_of(set_op(SetTarget::Attr(0))), "set");
        assert_eq!(name_of(Op::Boolean(BoolOp::Subtract)), "subtract");
    }
}
