//! CGA's operations: names, documented argument lists (which arguments are
//! selector keywords), blocks, families and a line on what each does, for
//! completion, hover and signature help. The engine checks and dispatches
//! calls with the same table.

pub use cga_engine::ops::table::{ArgMode, Block, Family, OpDef, Param, Status};

/// Every operation, in the order of the reference's index.
pub fn all() -> &'static [OpDef] {
    cga_engine::ops::table::OPERATIONS
}

/// The operation called `name` (or one of its other names, such as
/// `insert` for `i`).
pub fn find(name: &str) -> Option<&'static OpDef> {
    cga_engine::ops::table::find(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_describes_every_operation() {
        let extrude = find("extrude").unwrap();
        assert_eq!(extrude.status(), Status::Runs);
        assert_eq!(extrude.family, Family::Creation);
        assert_eq!(extrude.forms[1][0].name, "extrusionType");
        assert_eq!(extrude.forms[1][0].mode, ArgMode::Selector);
        assert_eq!(find("split").unwrap().block, Block::Parts);
        assert!(matches!(
            find("roof").unwrap().status(),
            Status::Deprecated(_)
        ));
        assert_eq!(
            find("setTagsFromEdgeAttrs").unwrap().status(),
            Status::NotRun
        );
        assert!(all().len() >= 80, "{} operations", all().len());
    }
}
