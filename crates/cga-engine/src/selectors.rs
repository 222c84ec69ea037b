//! Orientation selectors of CGA, shared by the component split (`comp`),
//! `geometry.area(selector)` and `geometry.isOriented(selector)`: which
//! direction class a face (or edge, or vertex) normal falls into, and the
//! tag queries of `isTagged`.
//!
//! Two families classify a normal:
//! - *quadrants* (`front back left right top bottom`, and their `object.*`,
//!   `world.*`, `street.*` forms): the normal's dominant axis in a frame. In
//!   the scope frame `front` is +z, `right` +x, `top` +y. The world frame has
//!   `world.south` = +z, `world.north` = -z, `world.east` = +x,
//!   `world.west` = -x, `world.up` = +y. `*.side` is any of the four
//!   horizontal quadrants. Ties between axes go to y (top/bottom), then z.
//! - *slopes* (`horizontal aslant vertical nutant`): the angle between the
//!   normal and the scope's xz-plane, in the ranges of the reference (in
//!   degrees): horizontal `]78.75, 90]` and `[-90, -78.75]`, aslant
//!   `]11.25, 78.75]`, vertical `]-11.25, 11.25]`, nutant `]-78.75, -11.25]`.
//!   `side` is everything but horizontal.
//!
//! `street.*` selectors need street-width data that lots here never carry,
//! so they fall back to the `object.*` selectors, as the reference says.
//! A zero normal (a degenerate face, an isolated point) matches no
//! orientation selector.

use cga_geometry::{DMat3, DVec3};

/// The frame a quadrant selector is read in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Space {
    /// The current shape's scope (`front`, `top`, ...).
    Scope,
    /// The initial shape's coordinate system (`object.front`, `street.*`).
    Object,
    /// The world (`world.south`, `world.up`, ...).
    World,
}

/// The direction class of a normal in a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quadrant {
    /// +z
    Front,
    /// -z
    Back,
    /// -x
    Left,
    /// +x
    Right,
    /// +y
    Top,
    /// -y
    Bottom,
    /// Any of front, back, left, right (only as a selector: `object.side`).
    Side,
    /// Back, left or right: the deprecated `noStreetSide` (only as a
    /// selector).
    SideNotFront,
}

/// The class of the angle between a normal and the xz-plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slope {
    Horizontal,
    Aslant,
    Vertical,
    Nutant,
}

/// The roof edge classes of `comp(e)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoofEdge {
    Eave,
    Hip,
    Valley,
    Ridge,
}

/// A selector keyword of a comp head (or an orientation argument).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Selector {
    Quadrant(Space, Quadrant),
    Slope(Slope),
    /// `side`: all but the horizontal components.
    Side,
    All,
    Border,
    Inside,
    Roof(RoofEdge),
    /// `isTagged(query)` / `isTagged(query, e|v)`; the arguments are
    /// evaluated by the caller.
    IsTagged,
}

impl Selector {
    /// The selector a keyword names, if it is one. `isTagged` is a call, not
    /// a keyword, and is not returned here.
    pub fn parse(name: &str) -> Option<Selector> {
        use Quadrant::*;
        use Selector as S;
        let quadrant = |s: &str| match s {
            "front" => Some(Front),
            "back" => Some(Back),
            "left" => Some(Left),
            "right" => Some(Right),
            "top" => Some(Top),
            "bottom" => Some(Bottom),
            _ => None,
        };
        if let Some(q) = quadrant(name) {
            return Some(S::Quadrant(Space::Scope, q));
        }
        if let Some(rest) = name
            .strip_prefix("object.")
            .or_else(|| name.strip_prefix("street."))
        {
            // Without street data, street.* is object.* (op_comp.md).
            return match rest {
                "side" => Some(S::Quadrant(Space::Object, Side)),
                _ => quadrant(rest).map(|q| S::Quadrant(Space::Object, q)),
            };
        }
        if let Some(rest) = name.strip_prefix("world.") {
            let q = match rest {
                "south" => Front,
                "north" => Back,
                "west" => Left,
                "east" => Right,
                "up" => Top,
                "down" => Bottom,
                "side" => Side,
                _ => return None,
            };
            return Some(S::Quadrant(Space::World, q));
        }
        Some(match name {
            // Deprecated since 2012.1 (cga_changelog.md) for the street.*
            // selectors; without street data the side facing the street is
            // the front, as street.front falls back to object.front.
            "streetSide" => S::Quadrant(Space::Object, Front),
            "noStreetSide" => S::Quadrant(Space::Object, SideNotFront),
            "horizontal" => S::Slope(Slope::Horizontal),
            "aslant" => S::Slope(Slope::Aslant),
            "vertical" => S::Slope(Slope::Vertical),
            "nutant" => S::Slope(Slope::Nutant),
            "side" => S::Side,
            "all" => S::All,
            "border" => S::Border,
            "inside" => S::Inside,
            "eave" => S::Roof(RoofEdge::Eave),
            "hip" => S::Roof(RoofEdge::Hip),
            "valley" => S::Roof(RoofEdge::Valley),
            "ridge" => S::Roof(RoofEdge::Ridge),
            _ => return None,
        })
    }

    /// True for the selectors decided by the normal alone (quadrants,
    /// slopes, `side`, `all`): the ones `geometry.area(selector)` and
    /// `geometry.isOriented(selector)` accept.
    pub fn is_orientation(self) -> bool {
        matches!(
            self,
            Selector::Quadrant(..) | Selector::Slope(_) | Selector::Side | Selector::All
        )
    }
}

/// The frames orientation selectors are read in, as rotations from the
/// frame a normal is given in: `scope` maps that frame's vectors to the
/// scope frame, and so on. For a normal given in a shape's scope-local
/// coordinates `scope` is the identity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frames {
    pub scope: DMat3,
    pub object: DMat3,
    pub world: DMat3,
}

impl Frames {
    /// Frames for normals given in the scope-local coordinates of a shape
    /// whose scope axes are `scope_axes` (object coordinates), in a
    /// derivation whose initial shape's frame has axes `object_axes`.
    /// Object coordinates are world coordinates in this engine.
    pub fn for_scope(scope_axes: DMat3, object_axes: DMat3) -> Frames {
        Frames {
            scope: DMat3::IDENTITY,
            object: object_axes.transpose() * scope_axes,
            world: scope_axes,
        }
    }

    /// True if `normal` (unit or zero, in the frame these frames map from)
    /// matches the orientation selector `sel`. Selectors that are not about
    /// orientation (border, roof edges, tags) never match here.
    pub fn matches(&self, sel: Selector, normal: DVec3) -> bool {
        if normal == DVec3::ZERO || !normal.is_finite() {
            return sel == Selector::All;
        }
        match sel {
            Selector::All => true,
            Selector::Quadrant(space, q) => {
                let m = match space {
                    Space::Scope => self.scope,
                    Space::Object => self.object,
                    Space::World => self.world,
                };
                quadrant_matches(q, quadrant_of(m * normal))
            }
            Selector::Slope(s) => slope_of(self.scope * normal) == s,
            Selector::Side => slope_of(self.scope * normal) != Slope::Horizontal,
            _ => false,
        }
    }
}

fn quadrant_matches(sel: Quadrant, q: Quadrant) -> bool {
    match sel {
        Quadrant::Side => matches!(
            q,
            Quadrant::Front | Quadrant::Back | Quadrant::Left | Quadrant::Right
        ),
        Quadrant::SideNotFront => matches!(q, Quadrant::Back | Quadrant::Left | Quadrant::Right),
        _ => sel == q,
    }
}

/// The quadrant of a non-zero direction: its dominant axis and sign. Ties
/// go to y, then z, then x.
pub fn quadrant_of(n: DVec3) -> Quadrant {
    let a = n.abs();
    if a.y >= a.x && a.y >= a.z {
        if n.y >= 0.0 {
            Quadrant::Top
        } else {
            Quadrant::Bottom
        }
    } else if a.z >= a.x {
        if n.z >= 0.0 {
            Quadrant::Front
        } else {
            Quadrant::Back
        }
    } else if n.x >= 0.0 {
        Quadrant::Right
    } else {
        Quadrant::Left
    }
}

/// The slope class of a non-zero direction: the angle between it and the
/// xz-plane, in the reference's ranges.
pub fn slope_of(n: DVec3) -> Slope {
    let len = n.length();
    let s = if len > 0.0 {
        (n.y / len).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let deg = s.asin().to_degrees();
    if deg > 78.75 || deg <= -78.75 {
        Slope::Horizontal
    } else if deg > 11.25 {
        Slope::Aslant
    } else if deg > -11.25 {
        Slope::Vertical
    } else {
        Slope::Nutant
    }
}

/// True if the tag query `query` matches `tag` (cga_componentTags.md):
/// both are dot-separated subtags; `?` matches exactly one subtag, `*` one
/// or more; a query also matches every tag it is a prefix of ("Facade"
/// matches "Facade.Front").
pub fn tag_matches(query: &str, tag: &str) -> bool {
    let q: Vec<&str> = query.split('.').collect();
    let t: Vec<&str> = tag.split('.').collect();
    if q.iter().any(|s| s.is_empty()) {
        return false;
    }
    prefix_match(&q, &t)
}

/// Whether the subtags `q` match a prefix of `t`.
fn prefix_match(q: &[&str], t: &[&str]) -> bool {
    let Some((first, rest)) = q.split_first() else {
        return true;
    };
    match *first {
        "*" => (1..=t.len()).any(|n| prefix_match(rest, &t[n..])),
        "?" => !t.is_empty() && prefix_match(rest, &t[1..]),
        name => t.first() == Some(&name) && prefix_match(rest, &t[1..]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_keyword_of_the_reference() {
        use Quadrant::*;
        assert_eq!(
            Selector::parse("front"),
            Some(Selector::Quadrant(Space::Scope, Front))
        );
        assert_eq!(
            Selector::parse("world.north"),
            Some(Selector::Quadrant(Space::World, Back))
        );
        assert_eq!(
            Selector::parse("world.east"),
            Some(Selector::Quadrant(Space::World, Right))
        );
        assert_eq!(
            Selector::parse("street.side"),
            Some(Selector::Quadrant(Space::Object, Side))
        );
        assert_eq!(
            Selector::parse("object.top"),
            Some(Selector::Quadrant(Space::Object, Top))
        );
        assert_eq!(Selector::parse("side"), Some(Selector::Side));
        assert_eq!(
            Selector::parse("valley"),
            Some(Selector::Roof(RoofEdge::Valley))
        );
        assert_eq!(Selector::parse("object.north"), None);
        assert_eq!(Selector::parse("world.front"), None);
        assert_eq!(Selector::parse("Front"), None);
    }

    #[test]
    fn quadrants_and_ties() {
        assert_eq!(quadrant_of(DVec3::new(0.1, 0.2, 0.9)), Quadrant::Front);
        assert_eq!(quadrant_of(DVec3::new(-0.9, 0.2, 0.1)), Quadrant::Left);
        assert_eq!(quadrant_of(DVec3::new(0.0, -1.0, 0.0)), Quadrant::Bottom);
        // 45 degrees between up and front: top wins; between front and right: front.
        assert_eq!(quadrant_of(DVec3::new(0.0, 1.0, 1.0)), Quadrant::Top);
        assert_eq!(quadrant_of(DVec3::new(1.0, 0.0, 1.0)), Quadrant::Front);
    }

    #[test]
    fn slope_ranges_follow_the_reference() {
        let at = |deg: f64| {
            let r = deg.to_radians();
            slope_of(DVec3::new(r.cos(), r.sin(), 0.0))
        };
        assert_eq!(at(90.0), Slope::Horizontal);
        assert_eq!(at(79.0), Slope::Horizontal);
        assert_eq!(at(78.0), Slope::Aslant);
        assert_eq!(at(12.0), Slope::Aslant);
        assert_eq!(at(11.0), Slope::Vertical);
        assert_eq!(at(0.0), Slope::Vertical);
        assert_eq!(at(-11.0), Slope::Vertical);
        assert_eq!(at(-12.0), Slope::Nutant);
        assert_eq!(at(-78.0), Slope::Nutant);
        assert_eq!(at(-79.0), Slope::Horizontal);
        assert_eq!(at(-90.0), Slope::Horizontal);
    }

    #[test]
    fn frames_read_scope_object_and_world() {
        // A scope turned 90 degrees about y: its +z is world +x.
        let scope = DMat3::from_rotation_y(std::f64::consts::FRAC_PI_2);
        let f = Frames::for_scope(scope, DMat3::IDENTITY);
        let n = DVec3::Z; // scope front
        assert!(f.matches(Selector::parse("front").unwrap(), n));
        assert!(f.matches(Selector::parse("world.east").unwrap(), n));
        assert!(f.matches(Selector::parse("object.right").unwrap(), n));
        assert!(f.matches(Selector::parse("world.side").unwrap(), n));
        assert!(!f.matches(Selector::parse("world.south").unwrap(), n));
        assert!(f.matches(Selector::Side, n));
        assert!(!f.matches(Selector::Side, DVec3::Y));
        assert!(!f.matches(Selector::parse("top").unwrap(), DVec3::ZERO));
        assert!(f.matches(Selector::All, DVec3::ZERO));
    }

    #[test]
    fn tag_queries() {
        assert!(tag_matches("Facade", "Facade.Front"));
        assert!(tag_matches("Facade.Front", "Facade.Front"));
        assert!(!tag_matches("Facade.Front", "Facade"));
        assert!(tag_matches("?.Front", "Facade.Front"));
        assert!(!tag_matches("?.Front", "Facade.TypeA.Front"));
        assert!(tag_matches("Facade.*.Left", "Facade.TypeA.Side.Left"));
        assert!(!tag_matches("Facade.*.Left", "Facade.Left"));
        assert!(tag_matches("envelope.side", "envelope.side.slope"));
        assert!(!tag_matches("envelope.side", "envelope.sides"));
        assert!(!tag_matches("", "x"));
    }
}
