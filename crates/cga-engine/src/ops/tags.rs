//! The component tag operations: `tag(name [, auto|faces|edges|vertices])`
//! and `deleteTags([query [, all|faces|edges|vertices]])`
//! (cga_componentTags.md; storage and queries in `cga_geometry::tags`).

use cga_geometry::tags::{self, TagQuery, TagTarget};
use cga_geometry::Mesh;

use super::transform::selector;
use super::TagOp;
use crate::derive::{Arg, RtError, ShapeState};

pub fn exec(st: &mut ShapeState, op: TagOp, args: &[Arg]) -> Result<(), RtError> {
    match op {
        TagOp::Tag => {
            let name = args[0].text()?;
            let target = match args.get(1) {
                Some(a) => target(a, &["auto", "faces", "edges", "vertices"])?,
                None => TagTarget::Auto,
            };
            if tags::clean_name(name).is_empty() {
                return Ok(());
            }
            edit(st, |m| tags::add_tag(m, name, target));
        }
        TagOp::DeleteTags => {
            let query = match args.first() {
                Some(a) => Some(TagQuery::parse(a.text()?)),
                None => None,
            };
            let target = match args.get(1) {
                Some(a) => target(a, &["all", "faces", "edges", "vertices"])?,
                None => TagTarget::All,
            };
            if !st.shape.geometry.local().may_have_tags() {
                return Ok(());
            }
            edit(st, |m| tags::delete_tags(m, query.as_ref(), target));
        }
    }
    Ok(())
}

fn target(a: &Arg, allowed: &[&str]) -> Result<TagTarget, RtError> {
    let s = selector(a, allowed)?;
    Ok(TagTarget::parse(s).unwrap_or(TagTarget::All))
}

/// Changes the tags of the shape's geometry (positions untouched).
fn edit(st: &mut ShapeState, f: impl FnOnce(&mut Mesh)) {
    if st.shape.geometry.is_empty() {
        return;
    }
    // In place where no other shape shares the mesh.
    f(st.shape.geometry.local_mut());
}
