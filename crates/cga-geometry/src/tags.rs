//! Component tags (CGA's "Geometry Tagging"): strings stored on the faces,
//! edges and vertices of a mesh, hierarchical with "." between subtags, and
//! the tag queries that select them.
//!
//! Storage: a mesh keeps a table of tag sets (`Mesh::tags`, entry 0 the
//! empty set, shared between derived meshes like the material slots); a
//! face refers to its set by `Face::tags`, a face edge and a face vertex by
//! the per-corner `Mesh::edge_tags` / `Mesh::vertex_tags` (absent when no
//! edge or vertex is tagged, so untagged geometry costs nothing). A shared
//! edge carries the union of its face edges' tags, a welded vertex the
//! union of its corners' tags.
//!
//! Propagation, as implemented (cga_componentTags.md, "Tag propagation"):
//! - face tags: kept by every derived face that copies its source face's
//!   material (cut pieces, extrude, offset/setback strips and insides,
//!   roofs, envelope, taper, convexify, cleanup, comp components, trim,
//!   innerRectangle, UV splits); cut caps get none; extrude sides also get
//!   the tags of the edge they rise from; the auto-tags of extrude, taper,
//!   the roofs and envelope replace that operation's earlier auto-tags;
//!   i, the primitives, footprint, resetGeometry, splitArea and
//!   reduceGeometry clear all tags;
//! - edge and vertex tags (per corner): kept by cut (pieces of tagged edges
//!   keep their tags; cut edges and new vertices get none), extrude (base
//!   and top edges keep theirs, vertical edges get their vertex's tags),
//!   offset/setback (strip fronts and backs and the remainder's edges get
//!   the tags of the lot edge they come from; setback adds its auto-tags),
//!   cleanup, merging, comp components, trim, reversing faces. Roofs,
//!   envelope, taper, convexify, splitAndSetbackPerimeter and UV splits
//!   drop them.
//!
//! Queries (`TagQuery`): "Facade" matches "Facade" and every tag below it
//! ("Facade.Front", "Facade.A.Left"); "?" matches exactly one subtag, "*"
//! one or more ("?.Front", "Facade.*.Left").

use std::sync::Arc;

use crate::mesh::Mesh;

/// A set of tags: sorted, without duplicates.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct TagSet(Vec<Arc<str>>);

impl TagSet {
    /// The set of `names` (sorted, duplicates and empty names dropped).
    pub fn from_names<I, S>(names: I) -> TagSet
    where
        I: IntoIterator<Item = S>,
        S: Into<Arc<str>>,
    {
        let mut v: Vec<Arc<str>> = names
            .into_iter()
            .map(Into::into)
            .filter(|s: &Arc<str>| !s.is_empty())
            .collect();
        v.sort_unstable();
        v.dedup();
        TagSet(v)
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    pub fn len(&self) -> usize {
        self.0.len()
    }

    pub fn iter(&self) -> impl Iterator<Item = &Arc<str>> + '_ {
        self.0.iter()
    }

    pub fn contains(&self, name: &str) -> bool {
        self.0.binary_search_by(|t| (**t).cmp(name)).is_ok()
    }

    /// This set with `name` added.
    pub fn with(&self, name: &Arc<str>) -> TagSet {
        match self.0.binary_search_by(|t| (**t).cmp(name)) {
            Ok(_) => self.clone(),
            Err(i) => {
                let mut v = self.0.clone();
                v.insert(i, name.clone());
                TagSet(v)
            }
        }
    }

    /// This set without the tags for which `drop` is true.
    pub fn without(&self, mut drop: impl FnMut(&str) -> bool) -> TagSet {
        TagSet(self.0.iter().filter(|t| !drop(t)).cloned().collect())
    }

    /// The union of both sets.
    pub fn union(&self, other: &TagSet) -> TagSet {
        if other.is_empty() {
            return self.clone();
        }
        if self.is_empty() {
            return other.clone();
        }
        let mut v = Vec::with_capacity(self.len() + other.len());
        v.extend(self.0.iter().cloned());
        v.extend(other.0.iter().cloned());
        v.sort_unstable();
        v.dedup();
        TagSet(v)
    }

    /// True if a tag of this set matches `query`.
    pub fn matches(&self, query: &TagQuery) -> bool {
        self.0.iter().any(|t| query.matches(t))
    }
}

/// A tag name as the `tag` operation stores it: the wildcard characters
/// `?` and `*` are filtered out (op_tag.md).
pub fn clean_name(name: &str) -> Arc<str> {
    if name.contains(['?', '*']) {
        name.chars()
            .filter(|&c| c != '?' && c != '*')
            .collect::<String>()
            .into()
    } else {
        name.into()
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
enum Part {
    Name(String),
    /// `?`: exactly one subtag.
    One,
    /// `*`: one or more subtags.
    Many,
}

/// A parsed tag query (see the module docs). The empty query matches every
/// tag.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TagQuery {
    parts: Vec<Part>,
}

impl TagQuery {
    pub fn parse(query: &str) -> TagQuery {
        let parts = if query.is_empty() {
            Vec::new()
        } else {
            query
                .split('.')
                .map(|s| match s {
                    "?" => Part::One,
                    "*" => Part::Many,
                    _ => Part::Name(s.to_string()),
                })
                .collect()
        };
        TagQuery { parts }
    }

    /// The query matching every tag.
    pub fn all() -> TagQuery {
        TagQuery { parts: Vec::new() }
    }

    /// True if the query matches `tag` or one of its ancestors (a leading
    /// run of its subtags).
    pub fn matches(&self, tag: &str) -> bool {
        if self.parts.is_empty() {
            return true;
        }
        // Subtags without allocating: at most a few per tag.
        let mut subs: [&str; 16] = [""; 16];
        let mut n = 0;
        for s in tag.split('.') {
            if n == subs.len() {
                // Deeper than any query reasonably reaches: compare the
                // general way.
                let all: Vec<&str> = tag.split('.').collect();
                return prefix_match(&self.parts, &all);
            }
            subs[n] = s;
            n += 1;
        }
        prefix_match(&self.parts, &subs[..n])
    }
}

/// True if `parts` matches a leading run of `subs` (at least one subtag
/// per part, exactly one for names and `?`).
fn prefix_match(parts: &[Part], subs: &[&str]) -> bool {
    match parts.split_first() {
        None => true,
        Some((Part::Name(n), rest)) => {
            subs.first().is_some_and(|s| s == n) && prefix_match(rest, &subs[1..])
        }
        Some((Part::One, rest)) => !subs.is_empty() && prefix_match(rest, &subs[1..]),
        Some((Part::Many, rest)) => (1..=subs.len()).any(|k| prefix_match(rest, &subs[k..])),
    }
}

/// Which components an operation on tags applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TagTarget {
    /// `tag`'s default: the highest-dimensional components (faces; the
    /// edges of edge shapes, the vertices of vertex shapes).
    Auto,
    Faces,
    Edges,
    Vertices,
    /// Faces, edges and vertices (`deleteTags`, `geometry.tags` default).
    All,
}

impl TagTarget {
    /// The target a selector keyword names (`auto faces edges vertices all`).
    pub fn parse(s: &str) -> Option<TagTarget> {
        Some(match s {
            "auto" => TagTarget::Auto,
            "faces" => TagTarget::Faces,
            "edges" => TagTarget::Edges,
            "vertices" => TagTarget::Vertices,
            "all" => TagTarget::All,
            _ => return None,
        })
    }

    fn resolve(self, mesh: &Mesh) -> TagTarget {
        if self != TagTarget::Auto {
            return self;
        }
        let widest = (0..mesh.faces.len())
            .map(|f| mesh.outer_loop(f).len)
            .max()
            .unwrap_or(3);
        match widest {
            0 | 1 => TagTarget::Vertices,
            2 => TagTarget::Edges,
            _ => TagTarget::Faces,
        }
    }

    fn faces(self) -> bool {
        matches!(self, TagTarget::Faces | TagTarget::All)
    }

    fn edges(self) -> bool {
        matches!(self, TagTarget::Edges | TagTarget::All)
    }

    fn vertices(self) -> bool {
        matches!(self, TagTarget::Vertices | TagTarget::All)
    }
}

impl Mesh {
    /// Tag set `i` of the table (the empty set if out of range).
    pub fn tag_set(&self, i: u32) -> &TagSet {
        static EMPTY: TagSet = TagSet(Vec::new());
        self.tags.get(i as usize).unwrap_or(&EMPTY)
    }

    /// The tags of face `f`.
    pub fn face_tags(&self, f: usize) -> &TagSet {
        self.tag_set(self.faces[f].tags)
    }

    /// The tag set index of the edge starting at `corner` (0: none).
    pub fn edge_tag_index(&self, corner: usize) -> u32 {
        self.edge_tags
            .as_ref()
            .and_then(|t| t.get(corner).copied())
            .unwrap_or(0)
    }

    /// The tag set index of the vertex at `corner` (0: none).
    pub fn vertex_tag_index(&self, corner: usize) -> u32 {
        self.vertex_tags
            .as_ref()
            .and_then(|t| t.get(corner).copied())
            .unwrap_or(0)
    }

    /// The tags of the face edge starting at `corner`.
    pub fn edge_tags_at(&self, corner: usize) -> &TagSet {
        self.tag_set(self.edge_tag_index(corner))
    }

    /// The tags of the face vertex at `corner`.
    pub fn vertex_tags_at(&self, corner: usize) -> &TagSet {
        self.tag_set(self.vertex_tag_index(corner))
    }

    /// True if some face, edge or vertex may carry a tag (a cheap test: the
    /// table has sets besides the empty one).
    pub fn may_have_tags(&self) -> bool {
        self.tags.iter().any(|s| !s.is_empty())
    }

    /// The index of `set` in the tag table, added if missing.
    pub fn intern_tags(&mut self, set: TagSet) -> u32 {
        if set.is_empty() {
            return 0;
        }
        if self.tags.is_empty() {
            self.tags.push(TagSet::default());
        }
        match self.tags.iter().position(|s| *s == set) {
            Some(i) => i as u32,
            None => {
                self.tags.push(set);
                self.tags.len() as u32 - 1
            }
        }
    }
}

/// Rewrites the tag sets of the components `target` names with `f` (which
/// sees each distinct set once), and rebuilds the table with only the sets
/// still used.
fn map_sets(mesh: &mut Mesh, target: TagTarget, mut f: impl FnMut(&TagSet) -> TagSet) {
    let target = target.resolve(mesh);
    let old = std::mem::replace(&mut mesh.tags, crate::mesh::no_tags());
    let get = |i: u32| old.get(i as usize).cloned().unwrap_or_default();
    let mut changed: Vec<u32> = vec![u32::MAX; old.len().max(1)];
    let mut kept: Vec<u32> = vec![u32::MAX; old.len().max(1)];
    let mut remap = |mesh: &mut Mesh, i: u32, apply: bool| -> u32 {
        let i = if (i as usize) < changed.len() { i } else { 0 };
        let memo = if apply { &mut changed } else { &mut kept };
        if memo[i as usize] == u32::MAX {
            let set = if apply { f(&get(i)) } else { get(i) };
            memo[i as usize] = mesh.intern_tags(set);
        }
        memo[i as usize]
    };
    for k in 0..mesh.faces.len() {
        let i = mesh.faces[k].tags;
        mesh.faces[k].tags = remap(mesh, i, target.faces());
    }
    for (which, apply) in [(0, target.edges()), (1, target.vertices())] {
        let list = if which == 0 {
            mesh.edge_tags.take()
        } else {
            mesh.vertex_tags.take()
        };
        let list = match list {
            Some(mut l) => {
                for t in l.iter_mut() {
                    *t = remap(mesh, *t, apply);
                }
                l
            }
            None if apply => {
                // Untagged components: apply `f` to the empty set once.
                let t = remap(mesh, 0, true);
                if t == 0 {
                    continue;
                }
                vec![t; mesh.corners.len()]
            }
            None => continue,
        };
        let list = (!list.iter().all(|&t| t == 0)).then_some(list);
        if which == 0 {
            mesh.edge_tags = list;
        } else {
            mesh.vertex_tags = list;
        }
    }
}

/// `tag(name, target)`: adds `name` (wildcards filtered out) to every
/// component of `target`.
pub fn add_tag(mesh: &mut Mesh, name: &str, target: TagTarget) {
    let name = clean_name(name);
    if name.is_empty() || mesh.faces.is_empty() {
        return;
    }
    map_sets(mesh, target, |s| s.with(&name));
}

/// `deleteTags(query, target)`: removes the tags `query` matches (all tags
/// without a query) from the components of `target`.
pub fn delete_tags(mesh: &mut Mesh, query: Option<&TagQuery>, target: TagTarget) {
    if !mesh.may_have_tags() {
        return;
    }
    map_sets(mesh, target, |s| match query {
        Some(q) => s.without(|t| q.matches(t)),
        None => TagSet::default(),
    });
}

/// Removes every tag of the mesh (operations that replace the geometry).
pub fn clear_tags(mesh: &mut Mesh) {
    for f in &mut mesh.faces {
        f.tags = 0;
    }
    mesh.edge_tags = None;
    mesh.vertex_tags = None;
    mesh.tags = crate::mesh::no_tags();
}

/// Applies an operation's auto-tags to the faces: face `f` loses the tags
/// under `family` (the same operation's earlier auto-tags, e.g. "extrude")
/// and gets `role(f)` ("extrude.top"), keeping its other tags.
pub fn set_face_auto_tags(
    mesh: &mut Mesh,
    family: &str,
    mut role: impl FnMut(usize) -> &'static str,
) {
    let q = TagQuery::parse(family);
    let mut memo: Vec<(u32, &'static str, u32)> = Vec::new();
    for f in 0..mesh.faces.len() {
        let old = mesh.faces[f].tags;
        let r = role(f);
        let new = match memo.iter().find(|m| m.0 == old && m.1 == r) {
            Some(m) => m.2,
            None => {
                let set = mesh
                    .tag_set(old)
                    .without(|t| q.matches(t))
                    .with(&Arc::from(r));
                let i = mesh.intern_tags(set);
                memo.push((old, r, i));
                i
            }
        };
        mesh.faces[f].tags = new;
    }
}

/// Sets per-corner edge auto-tags: the edge at corner `c` loses the tags
/// under `family` and gets `role(c)` (`None`: only the removal).
pub fn set_edge_auto_tags(
    mesh: &mut Mesh,
    family: &str,
    mut role: impl FnMut(usize) -> Option<&'static str>,
) {
    let q = TagQuery::parse(family);
    let n = mesh.corners.len();
    let mut list = mesh.edge_tags.take().unwrap_or_else(|| vec![0; n]);
    list.resize(n, 0);
    let mut memo: Vec<(u32, Option<&'static str>, u32)> = Vec::new();
    for (c, t) in list.iter_mut().enumerate() {
        let r = role(c);
        let old = *t;
        *t = match memo.iter().find(|m| m.0 == old && m.1 == r) {
            Some(m) => m.2,
            None => {
                let mut set = mesh.tag_set(old).without(|x| q.matches(x));
                if let Some(r) = r {
                    set = set.with(&Arc::from(r));
                }
                let i = mesh.intern_tags(set);
                memo.push((old, r, i));
                i
            }
        };
    }
    mesh.edge_tags = (!list.iter().all(|&t| t == 0)).then_some(list);
}

/// All tags of the components of `target` that `query` matches, sorted,
/// without duplicates (`geometry.tags`).
pub fn collect_tags(mesh: &Mesh, query: &TagQuery, target: TagTarget) -> Vec<Arc<str>> {
    let target = target.resolve(mesh);
    let mut used = vec![false; mesh.tags.len()];
    if target.faces() {
        for f in &mesh.faces {
            if let Some(u) = used.get_mut(f.tags as usize) {
                *u = true;
            }
        }
    }
    for (on, list) in [
        (target.edges(), &mesh.edge_tags),
        (target.vertices(), &mesh.vertex_tags),
    ] {
        if let (true, Some(list)) = (on, list) {
            for &t in list {
                if let Some(u) = used.get_mut(t as usize) {
                    *u = true;
                }
            }
        }
    }
    let mut out: Vec<Arc<str>> = mesh
        .tags
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u)
        .flat_map(|(s, _)| s.iter())
        .filter(|t| query.matches(t))
        .cloned()
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// Reorders the edge and vertex tags of the loop occupying `corners` when
/// the loop is reversed keeping its first corner (`c0 cn-1 .. c1`): vertex
/// tags move with their corners; the edge that started at `ci` now starts
/// at `ci+1`, which puts the edge tags in plain reverse order.
pub fn reverse_loop_tags(mesh: &mut Mesh, corners: std::ops::Range<usize>) {
    if let Some(e) = &mut mesh.edge_tags {
        if let Some(s) = e.get_mut(corners.clone()) {
            s.reverse();
        }
    }
    if let Some(v) = &mut mesh.vertex_tags {
        if let Some(s) = v.get_mut(corners.start + 1..corners.end) {
            s.reverse();
        }
    }
}

/// The index in `dst`'s table of every tag set of `src`'s table (sets
/// added to `dst` as needed): for merging meshes.
pub fn import_table(dst: &mut Mesh, src: &Mesh) -> Vec<u32> {
    if crate::mesh::SharedVec::ptr_eq(&dst.tags, &src.tags) {
        return (0..src.tags.len() as u32).collect();
    }
    src.tags
        .iter()
        .map(|s| dst.intern_tags(s.clone()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn q(s: &str) -> TagQuery {
        TagQuery::parse(s)
    }

    #[test]
    fn hierarchical_queries() {
        assert!(q("Facade").matches("Facade"));
        assert!(q("Facade").matches("Facade.Front"));
        assert!(q("Facade").matches("Facade.TypeA.Side.Left"));
        assert!(!q("Facade").matches("FacadeX"));
        assert!(!q("Facade").matches("Roof.Facade"));
        assert!(!q("Facade.Front").matches("Facade"));
        assert!(q("Facade.Front").matches("Facade.Front.Left"));
        assert!(!q("Facade.Front").matches("Facade.Side"));
        assert!(q("extrude.side").matches("extrude.side.inner"));
        assert!(!q("extrude.side").matches("extrude.top"));
    }

    #[test]
    fn wildcard_queries() {
        // ? is exactly one subtag.
        assert!(q("?.Front").matches("Facade.Front"));
        assert!(q("?.Front").matches("Wall.Front.Left"));
        assert!(!q("?.Front").matches("Front"));
        assert!(!q("?.Front").matches("A.B.Front"));
        assert!(q("?").matches("anything.at.all"));
        // * is one or more.
        assert!(q("Facade.*.Left").matches("Facade.A.Left"));
        assert!(q("Facade.*.Left").matches("Facade.A.B.C.Left"));
        assert!(!q("Facade.*.Left").matches("Facade.Left"));
        assert!(q("*.inner").matches("extrude.side.inner"));
        assert!(q("*.inner").matches("roof.side.inner"));
        assert!(!q("*.inner").matches("roof.side.outer"));
        assert!(!q("a.*").matches("a"));
        assert!(q("*").matches("x"));
        assert!(q("").matches("x"));
        // Deep tags take the general path.
        let deep = (0..20).map(|i| i.to_string()).collect::<Vec<_>>().join(".");
        assert!(q("0.*.19").matches(&deep));
        assert!(!q("0.*.20").matches(&deep));
    }

    #[test]
    fn names_lose_wildcards() {
        assert_eq!(&*clean_name("a*b?.c"), "ab.c");
        let s = TagSet::from_names(["b", "a", "b", ""]);
        assert_eq!(s.iter().map(|t| &**t).collect::<Vec<_>>(), ["a", "b"]);
        assert!(s.contains("a") && !s.contains("c"));
    }

    fn quad() -> Mesh {
        Mesh::polygon(&[
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(0.0, 0.0, -1.0),
        ])
    }

    #[test]
    fn tag_and_delete_per_component() {
        let mut m = quad();
        assert!(!m.may_have_tags());
        add_tag(&mut m, "Wall.A", TagTarget::Auto);
        add_tag(&mut m, "E", TagTarget::Edges);
        add_tag(&mut m, "V*", TagTarget::Vertices);
        assert_eq!(m.face_tags(0), &TagSet::from_names(["Wall.A"]));
        assert_eq!(m.edge_tags.as_ref().unwrap().len(), 4);
        assert!(m.edge_tags_at(3).contains("E"));
        assert!(m.vertex_tags_at(2).contains("V"));
        let all = collect_tags(&m, &TagQuery::all(), TagTarget::All);
        assert_eq!(
            all.iter().map(|t| &**t).collect::<Vec<_>>(),
            ["E", "V", "Wall.A"]
        );
        let faces = collect_tags(&m, &TagQuery::all(), TagTarget::Faces);
        assert_eq!(faces.len(), 1);
        delete_tags(&mut m, Some(&q("Wall")), TagTarget::All);
        assert!(m.face_tags(0).is_empty());
        assert!(m.edge_tags_at(0).contains("E"));
        delete_tags(&mut m, None, TagTarget::Edges);
        assert!(m.edge_tags.is_none());
        assert!(m.vertex_tags.is_some());
        delete_tags(&mut m, None, TagTarget::All);
        assert!(!m.may_have_tags());
        assert_eq!(m.tags.len(), 1);
    }

    #[test]
    fn auto_tags_replace_their_family_only() {
        let mut m = quad();
        add_tag(&mut m, "mine", TagTarget::Faces);
        set_face_auto_tags(&mut m, "extrude", |_| "extrude.top");
        set_face_auto_tags(&mut m, "extrude", |_| "extrude.bottom");
        assert_eq!(
            m.face_tags(0),
            &TagSet::from_names(["extrude.bottom", "mine"])
        );
        set_edge_auto_tags(&mut m, "setback", |c| (c == 0).then_some("setback.front"));
        assert!(m.edge_tags_at(0).contains("setback.front"));
        assert!(m.edge_tags_at(1).is_empty());
    }

    #[test]
    fn auto_target_of_edge_shapes_is_edges() {
        let mut e = Mesh::new();
        e.positions = vec![DVec3::ZERO, DVec3::X];
        e.add_face(&[&[0, 1]], 0);
        add_tag(&mut e, "x", TagTarget::Auto);
        assert!(e.face_tags(0).is_empty());
        assert!(e.edge_tags_at(0).contains("x"));
    }
}
