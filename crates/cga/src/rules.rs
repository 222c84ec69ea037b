//! Loading rule files into [`Rules`], and what can be asked of them.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use cga_engine::assets::{AssetStore, Assets};
use cga_engine::context::ContextUse;
use cga_engine::program::Program;
use cga_engine::{LoadOptions, Workspaces};
use cga_syntax::SourceMap;
use cga_world::{DiskWorld, World};

use crate::attributes::{Annotation, Attribute};
use crate::diagnostics::{Diagnostic, Location};
use crate::stack::on_big_stack;
use crate::Error;

/// Where rule files and everything they name are read from, and what was
/// read: rules loaded by one engine share its cache of assets, textures and
/// tables, so loading a file again after an edit reads only what changed.
#[derive(Clone)]
pub struct Engine {
    world: Arc<dyn World>,
    store: Arc<AssetStore>,
    /// Where workspace paths (`/Project/...`) are looked for, and the
    /// style rule files are loaded with.
    options: LoadOptions,
}

impl Engine {
    /// An engine reading from `world`.
    pub fn new(world: impl World + 'static) -> Engine {
        Engine::with_world(Arc::new(world))
    }

    /// An engine reading from a shared `world` (a [`MemoryWorld`](crate::MemoryWorld)
    /// an editor keeps changing, say).
    pub fn with_world(world: Arc<dyn World>) -> Engine {
        Engine {
            store: Arc::new(AssetStore::new(world.clone())),
            world,
            options: LoadOptions::default(),
        }
    }

    /// Sets the workspace folders (CityEngine workspaces: projects side by
    /// side) where imports, assets and textures named `/Project/...` are
    /// looked for after the rule file's own workspace (`--workspace`,
    /// `CGA_WORKSPACE`; see `cga_engine::locate`).
    pub fn workspaces(mut self, workspaces: Workspaces) -> Engine {
        self.options.workspaces = workspaces;
        self
    }

    /// Sets the style the main rule file is loaded with (`style Modern`
    /// in the file; `None` or `"Default"` for its default style). A style
    /// the file does not define is an error of the loaded rules naming
    /// the styles it does ([`Rules::styles`] lists them).
    pub fn style(mut self, style: Option<&str>) -> Engine {
        self.options.style = style.map(str::to_string);
        self
    }

    /// An engine reading files from disk.
    pub fn on_disk() -> Engine {
        Engine::new(DiskWorld)
    }

    /// Sets the largest asset file (OBJ, texts, tables) that is read, in
    /// MiB: larger ones are a warning, not read. Starts a new cache.
    pub fn max_asset_mib(self, mib: u64) -> Engine {
        Engine {
            store: Arc::new(AssetStore::new(self.world.clone()).with_max_file_mib(mib)),
            world: self.world,
            options: self.options,
        }
    }

    pub fn world(&self) -> &Arc<dyn World> {
        &self.world
    }

    /// Lots from specifications as [`lots::read_with`](crate::lots::read_with)
    /// takes them, every lot file read through this engine's world: lots
    /// from memory, or only from the folders of a confined world. (A
    /// GeoPackage must be a file on disk: SQLite opens it by its path.)
    pub fn read_lots(
        &self,
        specs: &[impl AsRef<str>],
        options: &crate::LotOptions,
    ) -> Result<crate::LotSet, crate::Error> {
        crate::lots::read_in(self.world.as_ref(), specs, options)
    }

    /// Loads the rule file at `path` and everything it imports. Always
    /// gives rules: a file with errors (even an unreadable one) gives what
    /// could be resolved, with the errors in [`Rules::diagnostics`].
    pub fn load(&self, path: impl AsRef<Path>) -> Rules {
        let path = path.as_ref();
        if is_package(path) {
            return self.load_package(path);
        }
        on_big_stack(|| {
            let mut sources = SourceMap::new();
            let loaded = cga_engine::load_with(&*self.world, path, &mut sources, &self.options);
            self.rules(path, loaded, sources)
        })
    }

    /// Loads rule text held in memory as if it were the file at `path`:
    /// its imports and assets are searched from there.
    pub fn load_text(&self, path: impl AsRef<Path>, text: impl Into<String>) -> Rules {
        let path = path.as_ref();
        let text = text.into();
        on_big_stack(|| {
            let mut sources = SourceMap::new();
            let loaded =
                cga_engine::load_text_with(&*self.world, path, text, &mut sources, &self.options);
            self.rules(path, loaded, sources)
        })
    }

    /// Loads a rule package (`.rpk`: a 7z or zip archive as CityEngine
    /// writes them): its files are seen under the package's own path
    /// (`city.rpk/rules/main.cga`, `city.rpk/assets/...`), over this
    /// engine's world, and its main rule file is loaded: the rule file of
    /// the package's one compiled rule (`bin/NAME.cgb`), else its only rule
    /// file.
    pub fn load_package(&self, path: impl AsRef<Path>) -> Rules {
        let path = path.as_ref();
        let fail = |message: String| {
            let loaded = cga_engine::Loaded {
                program: Program::default(),
                diagnostics: vec![cga_syntax::Diagnostic {
                    severity: cga_syntax::Severity::Error,
                    message,
                    span: None,
                    label: None,
                    notes: Vec::new(),
                }],
            };
            self.rules(path, loaded, SourceMap::new())
        };
        let bytes = match self.world.read(path) {
            Ok(b) => b,
            Err(e) => return fail(format!("cannot read rule package {}: {e}", path.display())),
        };
        let root = cga_world::normalize(path);
        let files = cga_world::MemoryWorld::over(self.world.clone());
        let names = match cga_world::mount_archive(&files, &root, &bytes) {
            Ok(n) => n,
            Err(e) => return fail(format!("cannot read rule package {}: {e}", path.display())),
        };
        let main = match package_main_rule(&names) {
            Ok(m) => m,
            Err(why) => return fail(format!("rule package {}: {why}", path.display())),
        };
        // The package's world holds its files: rules, assets and textures
        // are all read from there.
        let world: Arc<dyn World> = Arc::new(files);
        let engine = Engine {
            store: Arc::new(
                AssetStore::new(world.clone()).with_max_file_mib(self.store.max_file_mib()),
            ),
            world,
            options: self.options.clone(),
        };
        engine.load(root.join(main))
    }

    fn rules(&self, path: &Path, loaded: cga_engine::Loaded, sources: SourceMap) -> Rules {
        let diagnostics: Vec<Diagnostic> = loaded
            .diagnostics
            .iter()
            .map(|d| Diagnostic::new(d, &sources))
            .collect();
        let program = loaded.program;
        let assets = Assets::new(self.store.clone(), &sources)
            .with_workspaces(self.options.workspaces.clone());
        let context_use = ContextUse::of(&program);
        let mut rules = Rules {
            inner: Arc::new(Inner {
                path: path.to_path_buf(),
                has_errors: diagnostics.iter().any(Diagnostic::is_error),
                attributes: Vec::new(),
                diagnostics,
                program,
                sources,
                assets,
                context_use,
                engine: self.clone(),
                mesh_room: Default::default(),
            }),
        };
        let attributes = rules.read_attributes();
        if let Some(inner) = Arc::get_mut(&mut rules.inner) {
            inner.attributes = attributes;
        }
        rules
    }
}

/// A loaded rule file: its program, diagnostics and attributes. Cheap to
/// clone and safe to share between threads; generating does not change it.
#[derive(Clone)]
pub struct Rules {
    pub(crate) inner: Arc<Inner>,
}

pub(crate) struct Inner {
    pub path: PathBuf,
    pub program: Program,
    pub sources: SourceMap,
    pub diagnostics: Vec<Diagnostic>,
    pub has_errors: bool,
    pub attributes: Vec<Attribute>,
    pub assets: Assets,
    pub context_use: ContextUse,
    pub engine: Engine,
    /// The room each material's mesh took (by material in order of first
    /// use) in the lot last collected as plain meshes (with several
    /// workers, whichever finished last), which the next generation's
    /// collectors start with, bounded (`Rules::plain_collector`): a host
    /// calls again and again with lots much alike (the preview on every
    /// edit, Python per batch).
    pub mesh_room: std::sync::Mutex<Vec<(usize, usize)>>,
}

/// A rule of the rule files, as a library user names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RuleRef(pub(crate) u32);

/// Counts of what loaded rule files hold (over all imports; an import of
/// one file twice counts twice).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProgramSize {
    /// Rules ([`RuleRef`]s are below this number).
    pub rules: usize,
    pub attributes: usize,
    /// Functions and consts.
    pub functions: usize,
}

/// What the rules know of one rule.
#[derive(Clone, Debug, PartialEq)]
pub struct RuleInfo {
    /// The rule's name as written in its file.
    pub name: String,
    /// The import alias path of its file (`""` for the main file).
    pub prefix: String,
    pub arity: usize,
    pub annotations: Vec<Annotation>,
    pub location: Option<Location>,
}

impl Rules {
    /// The rule file's path.
    pub fn path(&self) -> &Path {
        &self.inner.path
    }

    /// Every error and warning found loading the file and its imports, in
    /// file order.
    pub fn diagnostics(&self) -> &[Diagnostic] {
        &self.inner.diagnostics
    }

    /// Whether the rules have errors (and so cannot generate).
    pub fn has_errors(&self) -> bool {
        self.inner.has_errors
    }

    /// The attributes of the main rule file, sorted by name.
    pub fn attributes(&self) -> &[Attribute] {
        &self.inner.attributes
    }

    pub fn attribute(&self, name: &str) -> Option<&Attribute> {
        self.inner.attributes.iter().find(|a| a.name == name)
    }

    /// The styles of the main rule file, `Default` first.
    pub fn styles(&self) -> &[String] {
        &self.inner.program.styles
    }

    /// The rules of the main rule file that can start a generation (no
    /// parameters), the one marked `@StartRule` (or `start`) first.
    pub fn start_rules(&self) -> Vec<String> {
        let p = &self.inner.program;
        let mut names: Vec<(bool, String)> = p
            .main_rules
            .iter()
            .map(|&(_, id)| &p.rules[id as usize])
            .filter(|r| r.arity == 0)
            .map(|r| {
                let marked = r.is_start || r.annotations.iter().any(|a| a.name == "StartRule");
                (!marked, r.name.clone())
            })
            .collect();
        names.sort_by_key(|(unmarked, _)| *unmarked);
        names.dedup_by(|a, b| a.1 == b.1);
        names.into_iter().map(|(_, n)| n).collect()
    }

    /// The start rule a generation with `name` uses: `name` if given, else
    /// the rule marked `@StartRule`, else `Lot`.
    pub fn start_rule(&self, name: Option<&str>) -> Result<RuleRef, Error> {
        self.inner
            .program
            .start_rule(name)
            .map(RuleRef)
            .map_err(Error::StartRule)
    }

    /// What the rules know of `rule`.
    pub fn rule(&self, rule: RuleRef) -> RuleInfo {
        let p = &self.inner.program;
        let r = &p.rules[rule.0 as usize];
        RuleInfo {
            name: r.name.clone(),
            prefix: p.rulesets[r.ruleset as usize].prefix.clone(),
            arity: r.arity,
            annotations: annotations(&r.annotations),
            location: self.location(r.span),
        }
    }

    /// How much the rule files and their imports hold.
    pub fn size(&self) -> ProgramSize {
        let p = &self.inner.program;
        ProgramSize {
            rules: p.rules.len(),
            attributes: p.attrs.len(),
            functions: p.functions.len(),
        }
    }

    /// The diagnostics rendered as the `cga` command prints them.
    pub fn render_diagnostics(&self) -> String {
        self.inner
            .diagnostics
            .iter()
            .map(Diagnostic::render)
            .collect()
    }

    pub(crate) fn location(&self, span: cga_syntax::Span) -> Option<Location> {
        let sources = &self.inner.sources;
        if sources.files().count() <= span.file.0 as usize {
            return None;
        }
        let file = sources.get(span.file);
        let (line, column) = file.line_col(span.start);
        let (end_line, end_column) = file.line_col(span.end);
        Some(Location {
            file: file.path.clone(),
            line,
            column,
            end_line,
            end_column,
            line_text: file.line_text(line).to_string(),
        })
    }

    /// Options for writing models of these rules: textures are read from
    /// the engine's world and searched, like CityEngine's exporters search
    /// them, in the rule file's folder and its ancestors (project roots)
    /// with their `assets/` folders.
    pub fn export_options(&self) -> cga_export::ExportOptions {
        let dir = self.inner.path.parent().unwrap_or(Path::new(""));
        let mut roots = Vec::new();
        for d in dir.ancestors() {
            roots.push(d.join("assets"));
            roots.push(d.to_path_buf());
        }
        cga_export::ExportOptions {
            texture_roots: roots,
            world: self.inner.engine.world.clone(),
            ..cga_export::ExportOptions::default()
        }
    }

    /// The engine these rules were loaded by.
    pub fn engine(&self) -> &Engine {
        &self.inner.engine
    }

    /// The error a generation with these rules fails with, if any.
    pub(crate) fn check_usable(&self) -> Result<(), Error> {
        if self.inner.has_errors {
            return Err(Error::Rules {
                path: self.inner.path.clone(),
                errors: self
                    .inner
                    .diagnostics
                    .iter()
                    .filter(|d| d.is_error())
                    .count(),
            });
        }
        Ok(())
    }

    fn read_attributes(&self) -> Vec<Attribute> {
        let p = &self.inner.program;
        let ids: Vec<u32> = p.main_attrs.iter().map(|&(_, id)| id).collect();
        // Defaults are evaluated on the default lot; a file with errors has
        // placeholders where its defaults did not resolve.
        let values = if self.inner.has_errors {
            vec![]
        } else {
            on_big_stack(|| {
                cga_engine::generate::attribute_values(
                    p,
                    &self.inner.assets,
                    &cga_engine::lot::rect(20.0, 30.0),
                    0,
                    &ids,
                )
            })
        };
        p.main_attrs
            .iter()
            .enumerate()
            .map(|(i, (name, id))| {
                let def = &p.attrs[*id as usize];
                let default = values.get(i).and_then(|v| v.as_ref().ok()).cloned();
                Attribute {
                    name: name.clone(),
                    ty: default.as_ref().map(cga_value::Value::value_type),
                    default,
                    annotations: annotations(&def.annotations),
                    location: self.location(def.span),
                    doc: self.doc_comment(def.span),
                }
            })
            .collect()
    }

    /// The comment lines right above the line of `span`, without markers.
    fn doc_comment(&self, span: cga_syntax::Span) -> Option<String> {
        let file = self.inner.sources.get(span.file);
        crate::syntax::doc_comment(&file.text, span.start as usize)
    }
}

/// Whether `path` names a rule package (by its extension).
fn is_package(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("rpk"))
}

/// The main rule file of a package with the files `names`: the rule file
/// of its one compiled rule (`bin/typology/x.cgb` is compiled from
/// `rules/typology/x.cga`; compiled imports carry a `$` in their name), else
/// its only rule file.
fn package_main_rule(names: &[String]) -> Result<String, String> {
    let cga: Vec<&String> = names
        .iter()
        .filter(|n| n.to_ascii_lowercase().ends_with(".cga") && !n.starts_with(".ws/"))
        .collect();
    let compiled: Vec<&str> = names
        .iter()
        .filter_map(|n| n.strip_prefix("bin/")?.strip_suffix(".cgb"))
        .filter(|stem| !stem.contains('$'))
        .collect();
    if let [stem] = compiled[..] {
        let wanted = format!("rules/{stem}.cga");
        if let Some(found) = cga.iter().find(|n| n.eq_ignore_ascii_case(&wanted)) {
            return Ok(found.to_string());
        }
    }
    match cga[..] {
        [only] => Ok(only.clone()),
        [] => Err("it holds no rule file (rules/*.cga)".into()),
        _ => Err(format!(
            "it holds {} rule files and no single compiled rule says which is the main one: {}",
            cga.len(),
            cga.iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

fn annotations(list: &[cga_engine::program::AnnotationInfo]) -> Vec<Annotation> {
    list.iter()
        .map(|a| Annotation {
            name: a.name.clone(),
            args: a.args.clone(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn a_package_main_rule_is_its_compiled_rule_else_its_only_rule_file() {
        let envelope = names(&[
            "bin/typology/envelope2002.cgb",
            "bin/typology/envelope2002$facade.cgb",
            "rules/typology/envelope2002.cga",
            "rules/typology/facade.cga",
            ".ws/ESRI.lib/rules/Plants/Plant_Loader.cga",
        ]);
        assert_eq!(
            package_main_rule(&envelope).unwrap(),
            "rules/typology/envelope2002.cga"
        );
        assert_eq!(
            package_main_rule(&names(&["rules/a.cga", "assets/x.obj"])).unwrap(),
            "rules/a.cga"
        );
        let two = package_main_rule(&names(&["rules/a.cga", "rules/b.cga"])).unwrap_err();
        assert!(two.contains("2 rule files"), "{two}");
        assert!(package_main_rule(&names(&["assets/x.obj"])).is_err());
    }
}
