//! The one-dimensional layout of CGA's `split`: where every part of a split pattern starts and how
//! long it is.
//!
//! The interpreter evaluates the size expressions of a `split(axis) { ... }` (or of `splitArea`,
//! `split(u|v, ...)`), records them in a [`SplitPattern`] and asks [`SplitLayouter::layout`] for the
//! parts. This module knows nothing of geometry or of the language: it turns sizes and a length `L`
//! (a scope extent, a uv range or, for `splitArea`, an area) into a list of [`Placed`] parts.
//!
//! # Building a pattern
//!
//! A pattern is written in source order: [`SplitPattern::push`] for every `size : operations`
//! entry, [`SplitPattern::open`] / [`SplitPattern::close`] around every nested `{ ... }` (with
//! `close(true)` for `{ ... }*`). The trailing `*` of the split itself is the `repeat` flag given to
//! [`SplitPattern::new`]. `push` returns the entry's *part id*: entries are numbered 0, 1, 2, ... in
//! source order, whatever their nesting, so the interpreter can keep the operations of entry `k` at
//! index `k` of a plain array and find them again from [`Placed::part`].
//!
//! ```
//! use cga_engine::split_layout::{layout, Size, SplitPattern};
//! // split(x) { 1 : X | { ~1 : Y | 0.2 : Z | ~1 : Y }* | 1 : X } on a scope of length 10
//! let mut p = SplitPattern::new(false);
//! p.push(Size::Absolute(1.0)); // part 0
//! p.open();
//! p.push(Size::Floating(1.0)); // part 1
//! p.push(Size::Absolute(0.2)); // part 2
//! p.push(Size::Floating(1.0)); // part 3
//! p.close(true).unwrap();
//! p.push(Size::Absolute(1.0)); // part 4
//! let parts = layout(&p, 10.0).unwrap();
//! assert_eq!(parts.len(), 14); // X, 4 x (Y Z Y), X
//! assert!((parts[1].size - 0.9).abs() < 1e-12); // the floating Y parts come out at 0.9
//! assert_eq!(parts[13].part, 4);
//! ```
//!
//! # The rules
//!
//! Sizes (all taken from CGA's `split` reference and the "subdivision split" manual page; every
//! worked example of both pages is a test in `tests/split_layout.rs`):
//!
//! * **absolute** `z`: the part is `z` long; **relative** `'r`: `r * L`, where `L` is always the
//!   length of the whole split, also inside nested `{...}` groups (a nested group is not a sub-shape,
//!   it has no length of its own). Absolute and relative sizes are *fixed* sizes.
//! * **floating** `~w`: floating parts share what the fixed parts leave, in proportion to `w`. All
//!   floating parts of a split, inside repeats or not, are scaled by one common factor `s`
//!   (the manual: in `~2 : Blue | { 1 : Green | ~2 : Blue }*` on 10 "the size of the first floating
//!   split and the size of the repetitive floating split is the same", 1.75).
//! * A size `<= 0` (fixed or floating) creates nothing and takes no room ("No splits will be produced
//!   with negative or zero-sized values").
//! * Parts are laid out from 0 in pattern order. A part that overflows `L` is cut to what is left;
//!   parts with no room left are not created (`'0.5 | '0.6 | 3` on 10: 5, 5, nothing). If the sizes
//!   sum to less than `L` and nothing floats, the rest stays empty (`'0.5 | '0.1 | '0.2`: gap 8..10).
//! * A non-repeated nested group `{ a | b }` is the same as writing `a | b` in its place.
//!
//! Repeats (`{ ... }*`, and the whole split when it ends in `*`). Each repeat at the top level of the
//! split (possibly inside non-repeated groups) is a *slot* whose content is repeated `n` times:
//!
//! 1. **Repeats of fixed sizes only** first take as many whole repetitions as fit into `L` minus
//!    the fixed parts outside repeats ("The repetitive absolute split will be evaluated first").
//!    Several such repeats take turns, one repetition each, while one still fits (round robin), so
//!    `1 | { 2 : G }* | { 1 : Y }* | 1` on 10 gives G G G Y Y between the borders (the pages give
//!    no numbers for parallel repeats). If the split has floating parts, the repeats then give
//!    repetitions back, one at a time from the one with the most, while that makes the floating
//!    parts less stretched (`|s - 1|`, rule 2); a tie keeps the repetition. So `{ 2 : Green }* |
//!    ~1 : Blue` on 10 is five Greens and no Blue ("the floating splits do not get any space"),
//!    while `~1 : Green | { 2 : Blue }* | ~1 : Green` on 10 is four Blues between Greens of 1,
//!    and Candler's pipe holders `~3 : NIL | { 0.3 : Holder | 4 : NIL }* | 0.3 : Holder | ~3 :
//!    NIL` get the count that keeps the margins nearest 3: with it the Candler pipes match
//!    CityEngine's output on both reference lots (taking every repetition that fits does not).
//! 2. **Repeats containing floating sizes** then get counts `n_j` that make the common floating
//!    scale `s = (L - fixed) / (sum of floating weights)` *least stretched*, i.e. minimise `|s - 1|`
//!    ("the number of repetitions and floating dimensions are adapted to the best solution (best
//!    number of repetitions and least stretching)"). Checks against the pages: `{ ~2.1 }*` on 10
//!    gives 5 parts of 2 (`|s-1|` = 0.048 against 0.19 for 4); `1 | { ~2.5 }* | 1` gives 3 parts of
//!    8/3; `1 | { ~1 | 0.2 | ~1 }* | 1` gives Y = 0.9; `~2 | { 1 | ~2 }*` gives 1.75. The measure is
//!    the *relative* deviation `|s - 1|`, not the absolute length deviation and not `|ln s|`: the
//!    rhythm example `{ 1 : X | ~2.7 : Y }* | 1 : X` on 10 is drawn with three Y (Y = 2,
//!    `|s-1|` = 0.259) rather than two (Y = 3.5, 0.296); `|ln s|` or rounding `9 / 3.7` would give
//!    two. (The older page writes that example with `~3`, which by any of these measures gives two
//!    repetitions of Y = 3.5; the newer page changed it to `~2.7`, matching its figure.)
//!    With several floating repeats the counts grow one repetition at a time in turns (round robin,
//!    first repeat first), as long as a step lowers `|s - 1|`: two parallel repeats of equal
//!    content end up with equal part sizes and counts that differ by at most one (the first gets
//!    the extra one). A step that only ties does not count as better: ties keep fewer repetitions.
//!    A repeat may end up with no repetition when that is the least stretched solution
//!    (`{ ~w : Window | d : Wall }* | ~w : Window` with one window's worth of space gives one window
//!    and no divider, as CGA facades rely on).
//! 3. If after that the split has no floating weight at all (no floating part outside repeats, no
//!    repetition of a floating repeat) and space is left, the fixed-only repeat whose turn it is in
//!    the round robin fills that space with one more repetition, cut at its end:
//!    `{ 2 : X | 1 : Y }*` on 10 is XYXYXY and "half a X" of length 1, and in
//!    `1 : A | { 2 : B }* | 1 : A` on 10.5 the last B is 0.5 long and the second A stays whole.
//!    The same cut makes a relative repeat `{ '0.3 }*` give 30/30/30/10 %, as `splitArea`'s page
//!    states. When there is no fixed-only repeat, a floating repeat of which not even one
//!    repetition fits gets that cut repetition (its floating parts have no room in it): `{ 1 : A |
//!    ~1 : B }*` on 0.5 is one A of 0.5, as the same split without `*` would be, rather than
//!    nothing.
//!
//! Nested repeats inside a repeat (`{ a | { b }* }*`) are laid out once per outer repetition (the
//! inner `*` is ignored): the pages describe no such pattern and give no numbers for it.
//!
//! # Indices
//!
//! [`Placed::index`] is `split.index`: the 0-based position of the part among all parts the split
//! creates, counted across repetitions and nesting ("Index and total are global"); `split.total` is
//! the number of placed parts. Parts that are not created (size <= 0, no room) get no index.
//!
//! # Floating point
//!
//! Whether something fits is decided with a tolerance of [`FIT_TOLERANCE`]` * L`, so that sums
//! such as `5 * '0.2` or `3 * 3.3 + 0.1` count as filling `L` exactly: a repetition that fits up
//! to rounding is taken, a rest that small is treated as nothing (floating parts get no room from
//! it, no cut repetition is made of it), and a part ending that close to the end of its space is
//! snapped to that end. So the last part ends exactly at `L` when floating parts fill the split,
//! and no 1e-15 sliver ever becomes a part. Positions are sums of the preceding sizes, each
//! repetition re-anchored at `start + r * period`, so they stay within a few ulps of `L` however
//! many repetitions there are. Each part carries its `end` as well as its `size`: in floating point
//! `start + size` can miss the intended end by an ulp (for some `a < b` no double `d` satisfies
//! `a + d == b`), so geometry should be cut at [`Placed::start`] and [`Placed::end`]; a part's
//! `end` is bit for bit the next part's `start`.

use std::fmt;

/// Relative tolerance (times the split length) used to decide whether something fits.
pub const FIT_TOLERANCE: f64 = 1e-9;

/// Largest number of parts one split may create. Patterns such as `{ 0.0001 : X }*` on a long
/// scope would otherwise allocate without bound; [`SplitLayouter::layout`] reports
/// [`LayoutError::TooManyParts`] instead.
pub const MAX_PARTS: usize = 1 << 20;

/// Improvement of `|s - 1|` below which a further repetition does not count as less stretched.
/// It makes exact ties (which the reference examples produce, e.g. 9/8 against 8.75/10) resolve
/// the same way whatever the rounding of the operands.
const STRETCH_EPSILON: f64 = 1e-12;

/// The size of one `size : operations` entry, as evaluated by the interpreter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Size {
    /// No prefix: the part is this long.
    Absolute(f64),
    /// `'` prefix, already as a fraction: `'0.5` is `Relative(0.5)`, i.e. half of the split length.
    Relative(f64),
    /// `~` prefix: a weight; floating parts share the space left by the fixed parts.
    Floating(f64),
}

/// Why a split could not be laid out.
#[derive(Clone, Debug, PartialEq)]
pub enum LayoutError {
    /// [`SplitPattern::close`] without a matching [`SplitPattern::open`], or a group left open.
    UnbalancedGroups,
    /// The split length is infinite or NaN.
    NonFiniteLength(f64),
    /// A size is infinite or NaN (typically a division by zero in the size expression).
    NonFiniteSize {
        /// The part id of the entry.
        part: usize,
        /// Its value.
        value: f64,
    },
    /// The split would create more than [`MAX_PARTS`] parts.
    TooManyParts {
        /// How many parts it would create (at least).
        parts: f64,
    },
}

impl fmt::Display for LayoutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LayoutError::UnbalancedGroups => write!(f, "unbalanced groups in split pattern"),
            LayoutError::NonFiniteLength(v) => write!(f, "split length is not finite ({v})"),
            LayoutError::NonFiniteSize { part, value } => {
                write!(f, "size of split part {part} is not finite ({value})")
            }
            LayoutError::TooManyParts { parts } => write!(
                f,
                "split would create {parts} parts, more than the limit of {MAX_PARTS}"
            ),
        }
    }
}

impl std::error::Error for LayoutError {}

/// One part created by a split.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    /// Part id of the pattern entry this part comes from (see [`SplitPattern::push`]); the
    /// interpreter runs that entry's operations on it.
    pub part: usize,
    /// Start along the split axis, from 0.
    pub start: f64,
    /// Length along the split axis, > 0 (`end - start`).
    pub size: f64,
    /// End along the split axis, `<= L`. Cut geometry at `start` and `end`: a part's `end` is
    /// bit for bit the next part's `start`, and the last part's `end` is exactly `L` when the
    /// parts fill the split, which `start + size` cannot always promise in floating point.
    pub end: f64,
    /// `split.index`: position among all created parts (equal to the position in the output).
    pub index: usize,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Item {
    Part {
        size: Size,
        part: u32,
    },
    /// Opening brace; `close` is the index of the matching [`Item::Close`] (patched by `close`).
    Open {
        repeat: bool,
        close: u32,
    },
    Close,
}

/// A split pattern: the evaluated sizes of a `split { ... }` in source order, with its nesting.
///
/// Reuse one pattern per thread ([`SplitPattern::reset`]) to avoid allocating per split.
#[derive(Clone, Debug, Default)]
pub struct SplitPattern {
    items: Vec<Item>,
    open_groups: Vec<u32>,
    parts: u32,
    repeat: bool,
    unbalanced: bool,
}

impl SplitPattern {
    /// An empty pattern; `repeat` is the trailing `*` of the split (`split(x) { ... }*`).
    pub fn new(repeat: bool) -> Self {
        SplitPattern {
            repeat,
            ..SplitPattern::default()
        }
    }

    /// Empties the pattern, keeping its buffers.
    pub fn reset(&mut self, repeat: bool) {
        self.items.clear();
        self.open_groups.clear();
        self.parts = 0;
        self.repeat = repeat;
        self.unbalanced = false;
    }

    /// Whether the whole split repeats (`{ ... }*`).
    pub fn is_repeat(&self) -> bool {
        self.repeat
    }

    /// Appends a `size : operations` entry and returns its part id (0, 1, 2, ... in call order).
    pub fn push(&mut self, size: Size) -> usize {
        let part = self.parts;
        self.parts += 1;
        self.items.push(Item::Part { size, part });
        part as usize
    }

    /// Opens a nested `{`.
    pub fn open(&mut self) {
        self.open_groups.push(self.items.len() as u32);
        self.items.push(Item::Open {
            repeat: false,
            close: 0,
        });
    }

    /// Closes the innermost nested group: `}` (`repeat == false`) or `}*` (`repeat == true`).
    pub fn close(&mut self, repeat: bool) -> Result<(), LayoutError> {
        let Some(open) = self.open_groups.pop() else {
            // Remember it so that `layout` refuses the pattern too.
            self.unbalanced = true;
            return Err(LayoutError::UnbalancedGroups);
        };
        let close = self.items.len() as u32;
        self.items[open as usize] = Item::Open { repeat, close };
        self.items.push(Item::Close);
        Ok(())
    }

    /// Number of entries pushed so far.
    pub fn part_count(&self) -> usize {
        self.parts as usize
    }

    fn check(&self, length: f64) -> Result<(), LayoutError> {
        if self.unbalanced || !self.open_groups.is_empty() {
            return Err(LayoutError::UnbalancedGroups);
        }
        if !length.is_finite() {
            return Err(LayoutError::NonFiniteLength(length));
        }
        for item in &self.items {
            if let Item::Part { size, part } = *item {
                let value = match size {
                    Size::Absolute(v) | Size::Relative(v) | Size::Floating(v) => v,
                };
                if !value.is_finite() {
                    return Err(LayoutError::NonFiniteSize {
                        part: part as usize,
                        value,
                    });
                }
            }
        }
        Ok(())
    }

    /// Iterates the top level of the split: parts outside any repeat, and repeats as slots.
    /// Non-repeated groups are flattened.
    fn level(&self) -> Level<'_> {
        Level {
            items: &self.items,
            next: 0,
            whole_is_repeat: self.repeat,
        }
    }

    /// The parts inside a slot's range, in order (nested groups flattened, nested repeats once).
    fn slot_parts(&self, begin: usize, end: usize) -> impl Iterator<Item = (Size, u32)> + '_ {
        self.items[begin..end]
            .iter()
            .filter_map(|item| match *item {
                Item::Part { size, part } => Some((size, part)),
                _ => None,
            })
    }
}

enum LevelItem {
    Part(Size, u32),
    /// A repeat; its content is `items[begin..end]`.
    Slot {
        begin: usize,
        end: usize,
    },
}

struct Level<'a> {
    items: &'a [Item],
    next: usize,
    whole_is_repeat: bool,
}

impl Iterator for Level<'_> {
    type Item = LevelItem;

    fn next(&mut self) -> Option<LevelItem> {
        if self.whole_is_repeat {
            // The whole split is one repeat slot.
            // (`next` counts the slots handed out: the items may be empty.)
            if self.next == 0 {
                self.next = 1;
                return Some(LevelItem::Slot {
                    begin: 0,
                    end: self.items.len(),
                });
            }
            return None;
        }
        while let Some(item) = self.items.get(self.next) {
            let here = self.next;
            self.next += 1;
            match *item {
                Item::Part { size, part } => return Some(LevelItem::Part(size, part)),
                Item::Open {
                    repeat: true,
                    close,
                } => {
                    self.next = close as usize + 1;
                    return Some(LevelItem::Slot {
                        begin: here + 1,
                        end: close as usize,
                    });
                }
                // Non-repeated groups are transparent.
                Item::Open { repeat: false, .. } | Item::Close => {}
            }
        }
        None
    }
}

/// What a size amounts to for a split of length `length`.
#[derive(Clone, Copy)]
enum Extent {
    Fixed(f64),
    Floating(f64),
    Nothing,
}

#[inline]
fn extent(size: Size, length: f64) -> Extent {
    match size {
        Size::Absolute(z) if z > 0.0 => Extent::Fixed(z),
        Size::Relative(r) if r > 0.0 => Extent::Fixed(r * length),
        Size::Floating(w) if w > 0.0 => Extent::Floating(w),
        _ => Extent::Nothing,
    }
}

/// Per-repeat bookkeeping of one layout.
#[derive(Clone, Copy, Debug)]
struct Slot {
    begin: usize,
    end: usize,
    /// Sum of the fixed sizes of one repetition.
    fixed: f64,
    /// Sum of the floating weights of one repetition.
    floating: f64,
    /// Parts one repetition creates at most.
    parts: usize,
    /// Chosen number of whole repetitions.
    count: u64,
    /// Gets one more, cut, repetition filling the rest (rule 3).
    partial: bool,
}

impl Slot {
    fn is_fixed_only(&self) -> bool {
        self.floating == 0.0 && self.fixed > 0.0
    }
    fn is_floating(&self) -> bool {
        self.floating > 0.0
    }
}

/// Reusable scratch space for laying out splits (one per thread).
#[derive(Clone, Debug, Default)]
pub struct SplitLayouter {
    slots: Vec<Slot>,
    /// Rule 1b's candidates: the counts being tried, a copy of them that
    /// rule 2 completes, and the best so far (kept to spare the
    /// allocations of a facade's thousands of splits).
    candidate: Vec<Slot>,
    trial: Vec<Slot>,
    best: Vec<Slot>,
}

/// Lays out `pattern` on `length` into a new vector. Convenience for [`SplitLayouter::layout`].
pub fn layout(pattern: &SplitPattern, length: f64) -> Result<Vec<Placed>, LayoutError> {
    let mut out = Vec::new();
    SplitLayouter::default().layout(pattern, length, &mut out)?;
    Ok(out)
}

impl SplitLayouter {
    /// New scratch space.
    pub fn new() -> Self {
        Self::default()
    }

    /// Lays out `pattern` on a split of length `length` (a scope extent, uv range or area).
    ///
    /// `out` is cleared and receives the created parts in order; `out[i].index == i`, and
    /// `out.len()` is `split.total`. A length `<= 0` creates no part.
    pub fn layout(
        &mut self,
        pattern: &SplitPattern,
        length: f64,
        out: &mut Vec<Placed>,
    ) -> Result<(), LayoutError> {
        out.clear();
        pattern.check(length)?;
        if length <= 0.0 {
            return Ok(());
        }
        let tol = FIT_TOLERANCE * length;

        // Top level: fixed sizes and floating weights outside repeats, and the repeat slots.
        self.slots.clear();
        let mut fixed_outside = 0.0;
        let mut floating_outside = 0.0;
        let mut parts_outside = 0usize;
        for item in pattern.level() {
            match item {
                LevelItem::Part(size, _) => match extent(size, length) {
                    Extent::Fixed(z) => {
                        fixed_outside += z;
                        parts_outside += 1;
                    }
                    Extent::Floating(w) => {
                        floating_outside += w;
                        parts_outside += 1;
                    }
                    Extent::Nothing => {}
                },
                LevelItem::Slot { begin, end } => {
                    let mut slot = Slot {
                        begin,
                        end,
                        fixed: 0.0,
                        floating: 0.0,
                        parts: 0,
                        count: 0,
                        partial: false,
                    };
                    for (size, _) in pattern.slot_parts(begin, end) {
                        match extent(size, length) {
                            Extent::Fixed(z) => {
                                slot.fixed += z;
                                slot.parts += 1;
                            }
                            Extent::Floating(w) => {
                                slot.floating += w;
                                slot.parts += 1;
                            }
                            Extent::Nothing => {}
                        }
                    }
                    self.slots.push(slot);
                }
            }
        }

        // 1. Fixed-only repeats take whole repetitions, in turns, before anything floats.
        let mut rest = length - fixed_outside;
        let mut budget = Budget::new(parts_outside);
        let next_turn = self.assign_fixed_repeats(&mut rest, tol, &mut budget)?;
        // 1b. With floating parts in the split, fixed-only repeats give back repetitions
        //     while that makes the floating parts less stretched.
        if floating_outside > 0.0 || self.slots.iter().any(|s| s.is_floating()) {
            self.balance_fixed_repeats(&mut rest, floating_outside, tol, &mut budget)?;
        }

        // 2. Repeats with floating parts: least stretching of the common floating scale.
        let floating = assign_floating_repeats(
            &mut self.slots,
            &mut rest,
            floating_outside,
            tol,
            &mut budget,
        )?;

        // 3. Nothing floats and space is left: the next fixed-only repeat fills it, cut.
        let scale = if floating > 0.0 && rest > tol {
            rest / floating
        } else {
            0.0
        };
        let mut partial_length = 0.0;
        if floating == 0.0 && rest > tol {
            // (With no fixed-only repeat, a floating repeat none of whose repetitions fit gets
            // the cut repetition: its fixed parts cover the space instead of leaving a hole.)
            let candidate = next_turn.or_else(|| {
                self.slots
                    .iter()
                    .position(|s| s.is_floating() && s.count == 0)
            });
            if let Some(j) = candidate {
                self.slots[j].partial = true;
                partial_length = rest;
                budget.add(self.slots[j].parts as f64)?;
            }
        }

        // Placement, in pattern order.
        out.reserve(budget.parts as usize);
        let mut placer = Placer {
            out,
            cursor: 0.0,
            length,
            tol,
        };
        let mut slot_index = 0;
        for item in pattern.level() {
            match item {
                LevelItem::Part(size, part) => placer.place_extent(size, part, scale, length),
                LevelItem::Slot { .. } => {
                    let slot = self.slots[slot_index];
                    slot_index += 1;
                    // Repetition r ends at slot_start + (r + 1) * period: anchoring every
                    // repetition there keeps the rounding error of positions at a few ulps
                    // instead of growing with the number of repetitions.
                    let slot_start = placer.cursor;
                    let period = slot.fixed + scale * slot.floating;
                    for r in 0..slot.count {
                        for (size, part) in pattern.slot_parts(slot.begin, slot.end) {
                            placer.place_extent(size, part, scale, length);
                        }
                        placer.anchor(slot_start + (r + 1) as f64 * period);
                    }
                    if slot.partial {
                        let limit = (placer.cursor + partial_length).min(length);
                        for (size, part) in pattern.slot_parts(slot.begin, slot.end) {
                            if let Extent::Fixed(z) = extent(size, length) {
                                placer.place(z, part, limit);
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Rule 1: whole repetitions for fixed-only repeats, one per repeat in turn while one fits into
    /// `rest`. Returns the repeat whose turn is next (it gets the cut repetition of rule 3).
    fn assign_fixed_repeats(
        &mut self,
        rest: &mut f64,
        tol: f64,
        budget: &mut Budget,
    ) -> Result<Option<usize>, LayoutError> {
        let mut cycle_fixed = 0.0;
        let mut cycle_parts = 0usize;
        let mut first = None;
        for (j, slot) in self.slots.iter().enumerate() {
            if slot.is_fixed_only() {
                cycle_fixed += slot.fixed;
                cycle_parts += slot.parts;
                first.get_or_insert(j);
            }
        }
        let Some(first) = first else {
            return Ok(None);
        };
        // Whole rounds of the round robin at once: each round gives every repeat one repetition.
        let rounds = if *rest > 0.0 {
            ((*rest + tol) / cycle_fixed).floor()
        } else {
            0.0
        };
        budget.add(rounds * cycle_parts as f64)?;
        let rounds = rounds as u64;
        for slot in self.slots.iter_mut().filter(|s| s.is_fixed_only()) {
            slot.count = rounds;
        }
        *rest -= rounds as f64 * cycle_fixed;
        // The last, incomplete round(s): repeats that still fit take one more in turn.
        let mut next_turn = first;
        loop {
            let mut progress = false;
            for j in 0..self.slots.len() {
                let slot = self.slots[j];
                if slot.is_fixed_only() && slot.fixed <= *rest + tol {
                    budget.add(slot.parts as f64)?;
                    self.slots[j].count += 1;
                    *rest -= slot.fixed;
                    progress = true;
                    next_turn = self.next_fixed_only(j);
                }
            }
            if !progress {
                break;
            }
        }
        Ok(Some(next_turn))
    }

    /// The fixed-only repeat after `j` in round-robin order.
    fn next_fixed_only(&self, j: usize) -> usize {
        let k = self.slots.len();
        (1..=k)
            .map(|d| (j + d) % k)
            .find(|&i| self.slots[i].is_fixed_only())
            .unwrap_or(j)
    }

    /// Rule 1b: when the split has floating parts, a fixed-only repeat does not take every
    /// repetition that fits: repetitions are given back, one at a time from the repeat with the
    /// most, while that lowers the floating parts' stretch `|s - 1|` (found with rule 2 applied
    /// to each candidate). Ties keep the repetitions, so `{ 2 : Green }* | ~1 : Blue` on 10 is
    /// five Greens and no Blue, as the split pages state, while `~1 : Green | { 2 : Blue }* |
    /// ~1 : Green` on 10 is four Blues between Greens of 1, and the candler rule's pipe holders
    /// `~3 : NIL | { 0.3 : Holder | 4 : NIL }* | 0.3 : Holder | ~3 : NIL` get the count that keeps
    /// the margins nearest 3 (the count CityEngine generates: its areas match).
    fn balance_fixed_repeats(
        &mut self,
        rest: &mut f64,
        floating_outside: f64,
        tol: f64,
        budget: &mut Budget,
    ) -> Result<(), LayoutError> {
        let trial = |slots: &[Slot], into: &mut Vec<Slot>, rest: f64| -> f64 {
            into.clear();
            into.extend_from_slice(slots);
            let mut rest = rest;
            let mut scratch = Budget::new(0);
            match assign_floating_repeats(into, &mut rest, floating_outside, tol, &mut scratch) {
                Ok(floating) => stretch(rest, floating, tol),
                Err(_) => f64::INFINITY,
            }
        };
        let SplitLayouter {
            slots: own,
            candidate: slots,
            trial: tried,
            best: best_slots,
        } = self;
        slots.clear();
        slots.extend_from_slice(own);
        best_slots.clear();
        best_slots.extend_from_slice(slots);
        let mut r = *rest;
        let mut best = (trial(slots, tried, r), r);
        let mut previous = best.0;
        // Each give-back raises the floating scale; past its best the stretch only grows.
        for _ in 0..MAX_PARTS {
            let Some(j) = (0..slots.len())
                .filter(|&j| slots[j].is_fixed_only() && slots[j].count > 0)
                .max_by_key(|&j| (slots[j].count, j))
            else {
                break;
            };
            slots[j].count -= 1;
            r += slots[j].fixed;
            let st = trial(slots, tried, r);
            if st < best.0 - STRETCH_EPSILON {
                best = (st, r);
                best_slots.clear();
                best_slots.extend_from_slice(slots);
            } else if st > previous + STRETCH_EPSILON {
                break;
            }
            previous = st;
        }
        let (_, chosen_rest) = best;
        let given_back: usize = own
            .iter()
            .zip(best_slots.iter())
            .map(|(a, b)| (a.count - b.count) as usize * a.parts)
            .sum();
        budget.add(-(given_back as f64))?;
        std::mem::swap(own, best_slots);
        *rest = chosen_rest;
        Ok(())
    }
}

/// Rule 2: repetition counts of the floating repeats minimising `|s - 1|`. Takes their fixed
/// sizes out of `rest` and returns the total floating weight of the split.
fn assign_floating_repeats(
    slots: &mut [Slot],
    rest: &mut f64,
    floating_outside: f64,
    tol: f64,
    budget: &mut Budget,
) -> Result<f64, LayoutError> {
    let mut cycle_fixed = 0.0;
    let mut cycle_floating = 0.0;
    let mut cycle_parts = 0usize;
    for slot in slots.iter().filter(|s| s.is_floating()) {
        cycle_fixed += slot.fixed;
        cycle_floating += slot.floating;
        cycle_parts += slot.parts;
    }
    let mut floating = floating_outside;
    if cycle_floating == 0.0 {
        return Ok(floating);
    }
    // Every step of the round robin lowers s, so while s stays >= 1 each step improves: whole
    // rounds up to s = 1 (solving (rest - n F) / (W + n G) = 1) are taken at once, exactly as
    // the one-step-at-a-time search would take them.
    let mut rounds = ((*rest - floating) / (cycle_fixed + cycle_floating)).floor();
    if cycle_fixed > 0.0 {
        rounds = rounds.min(((*rest + tol) / cycle_fixed).floor());
    }
    let rounds = rounds.max(0.0);
    budget.add(rounds * cycle_parts as f64)?;
    let rounds = rounds as u64;
    for slot in slots.iter_mut().filter(|s| s.is_floating()) {
        slot.count = rounds;
    }
    *rest -= rounds as f64 * cycle_fixed;
    floating += rounds as f64 * cycle_floating;

    // Then single steps, repeat after repeat, while one makes the split less stretched.
    let mut current = stretch(*rest, floating, tol);
    loop {
        let mut progress = false;
        for slot in slots.iter_mut().filter(|s| s.is_floating()) {
            let next_rest = *rest - slot.fixed;
            if next_rest < -tol {
                continue; // its fixed parts no longer fit
            }
            let next_floating = floating + slot.floating;
            let next_stretch = stretch(next_rest, next_floating, tol);
            if next_stretch < current - STRETCH_EPSILON {
                budget.add(slot.parts as f64)?;
                slot.count += 1;
                *rest = next_rest;
                floating = next_floating;
                current = next_stretch;
                progress = true;
            }
        }
        if !progress {
            break;
        }
    }
    Ok(floating)
}

/// `|s - 1|` for the floating scale `s = rest / floating`; a split where nothing floats is
/// perfect if nothing is left over and infinitely bad otherwise (any floating part is better).
#[inline]
fn stretch(rest: f64, floating: f64, tol: f64) -> f64 {
    if floating > 0.0 {
        (rest.max(0.0) / floating - 1.0).abs()
    } else if rest <= tol {
        0.0
    } else {
        f64::INFINITY
    }
}

/// Counts the parts a layout will create, to refuse runaway repeats before allocating.
struct Budget {
    parts: f64,
}

impl Budget {
    fn new(parts: usize) -> Self {
        Budget {
            parts: parts as f64,
        }
    }

    fn add(&mut self, parts: f64) -> Result<(), LayoutError> {
        self.parts += parts;
        if self.parts > MAX_PARTS as f64 {
            Err(LayoutError::TooManyParts { parts: self.parts })
        } else {
            Ok(())
        }
    }
}

struct Placer<'a> {
    out: &'a mut Vec<Placed>,
    cursor: f64,
    length: f64,
    tol: f64,
}

impl Placer<'_> {
    #[inline]
    fn place_extent(&mut self, size: Size, part: u32, scale: f64, length: f64) {
        match extent(size, length) {
            Extent::Fixed(z) => self.place(z, part, self.length),
            Extent::Floating(w) => self.place(w * scale, part, self.length),
            Extent::Nothing => {}
        }
    }

    /// Places a part of length `size` at the cursor, cut at `limit`; parts of no length and parts
    /// with no room are not created and take no room.
    #[inline]
    fn place(&mut self, size: f64, part: u32, limit: f64) {
        if size <= 0.0 || self.cursor >= limit - self.tol {
            return;
        }
        let start = self.cursor;
        let mut end = start + size;
        if end >= limit - self.tol {
            // Cut at the end of the space, or snap to it when it fits up to rounding.
            end = limit;
        }
        if end <= start {
            return; // a size below the resolution of the position
        }
        self.out.push(Placed {
            part: part as usize,
            start,
            size: end - start,
            end,
            index: self.out.len(),
        });
        self.cursor = end;
    }

    /// Moves the end of the last part (which is at the cursor) to `target`, the exact end of a
    /// repetition, when the two differ by rounding only. A part snapped to the split's end stays.
    #[inline]
    fn anchor(&mut self, target: f64) {
        if self.cursor == self.length
            || target > self.length
            || (target - self.cursor).abs() > self.tol
        {
            return;
        }
        if let Some(last) = self.out.last_mut() {
            if last.end == self.cursor && target > last.start {
                last.end = target;
                last.size = target - last.start;
                self.cursor = target;
            }
        }
    }
}
