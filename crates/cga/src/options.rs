//! How to generate: seed, start rule, attribute values, limits, threads,
//! cancellation.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

pub use cga_engine::Limits;
use cga_value::Value;

/// How lots are generated. `Options::default()` generates with the rule
/// file's own start rule and attribute defaults, seed 0, the default limits
/// and a thread per core.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// The run's random seed: the first lot derives with this seed (its
    /// `seedian`), every other lot with a hash of it and the lot's index,
    /// so that each seed gives a different city. A lot's own `seed`
    /// property (GIS data), or the attribute value `seed` when the rules
    /// declare no attribute of that name, sets the lots' seeds instead.
    pub seed: u64,
    /// The start rule; `None`: the rule marked `@StartRule`, else `Lot`.
    pub start_rule: Option<String>,
    /// Attribute values by name, for every lot (over lot attributes such
    /// as GeoJSON properties). A value of another type than the attribute's
    /// is converted to it where it reads as one (`"20"` for a float).
    pub attrs: Vec<(String, Value)>,
    pub limits: Limits,
    /// Threads deriving lots; `None`: one per core. The output does not
    /// depend on it.
    pub jobs: Option<usize>,
    /// Stops a running generation from another thread.
    pub cancel: Option<Cancel>,
    /// The index of each lot given in a larger run (a city generated in
    /// parts: tiles, partitions): lot `i` of the call derives with the seed
    /// of lot `lot_indices[i]` and its results carry that index, so the
    /// parts make the city one call would. `None`: their positions. Must
    /// have one index per lot.
    pub lot_indices: Option<std::sync::Arc<[usize]>>,
    /// The run's scene for context queries between lots (`inter`), made by
    /// [`Rules::scene`](crate::Rules::scene) over all its lots, for parts
    /// given with [`Options::lot_indices`]: each part's lots then see every
    /// lot of the run, not only the part's. `None`: the lots of the call.
    pub scene: Option<crate::Scene>,
}

impl Options {
    /// The index of lot `i` of a call ([`Options::lot_indices`]).
    pub(crate) fn lot_index(&self, i: usize) -> usize {
        self.lot_indices
            .as_ref()
            .map_or(i, |v| v.get(i).copied().unwrap_or(i))
    }

    pub fn seed(mut self, seed: u64) -> Options {
        self.seed = seed;
        self
    }

    pub fn start_rule(mut self, name: impl Into<String>) -> Options {
        self.start_rule = Some(name.into());
        self
    }

    /// Sets attribute `name` to `value` (replacing an earlier setting).
    pub fn attr(mut self, name: impl Into<String>, value: impl Into<Value>) -> Options {
        let name = name.into();
        self.attrs.retain(|(n, _)| *n != name);
        self.attrs.push((name, value.into()));
        self
    }

    pub fn limits(mut self, limits: Limits) -> Options {
        self.limits = limits;
        self
    }

    pub fn jobs(mut self, jobs: usize) -> Options {
        self.jobs = Some(jobs.max(1));
        self
    }

    pub fn cancel(mut self, cancel: Cancel) -> Options {
        self.cancel = Some(cancel);
        self
    }

    /// The number of threads to derive on.
    pub(crate) fn threads(&self) -> usize {
        self.jobs
            .unwrap_or_else(|| {
                std::thread::available_parallelism()
                    .map(|n| n.get())
                    .unwrap_or(1)
            })
            .max(1)
    }
}

/// A switch that stops a generation: clone it into [`Options::cancel`],
/// call [`Cancel::cancel`] from any thread, and the generation returns
/// [`Error::Cancelled`](crate::Error::Cancelled) within milliseconds (the
/// derivation looks at it where it looks at its time limit).
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    pub fn new() -> Cancel {
        Cancel::default()
    }

    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    pub(crate) fn flag(&self) -> Arc<AtomicBool> {
        self.0.clone()
    }
}
