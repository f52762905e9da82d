//! The engine's process-wide caches: geometries, step factors, interpolations, mass inverses and
//! CFL bounds are built once per key and shared by concurrent and serial runs (the keys are the
//! run's own text, so a hit is the same operator bit for bit).

use std::sync::{Arc, Mutex, OnceLock};

use crate::scene::FeSetup;

/// A process-wide cache: entries shared by concurrent runs (a second run waits for the first to
/// finish building) and kept for the next `CAP` distinct keys, so serial runs reuse them too.
pub(super) struct Cache<T> {
    pub(super) entries: Mutex<Vec<(String, Slot<T>)>>,
}

/// One cache entry: built once, by the first run that asks for it.
pub(super) type Slot<T> = Arc<OnceLock<Result<Arc<T>, String>>>;

impl<T> Cache<T> {
    const CAP: usize = 4;

    pub(super) const fn new() -> Self {
        Cache {
            entries: Mutex::new(Vec::new()),
        }
    }

    /// The value for `key`, built by `make` if absent; the flag says whether it was a hit.
    pub(super) fn get(
        &self,
        key: String,
        make: impl FnOnce() -> Result<T, String>,
    ) -> (Result<Arc<T>, String>, bool) {
        let cell = {
            let mut e = self.entries.lock().unwrap_or_else(|p| p.into_inner());
            match e.iter().position(|(k, _)| *k == key) {
                Some(i) => {
                    let entry = e.remove(i);
                    let cell = Arc::clone(&entry.1);
                    e.push(entry);
                    cell
                }
                None => {
                    let cell = Arc::new(OnceLock::new());
                    e.push((key, Arc::clone(&cell)));
                    if e.len() > Self::CAP {
                        e.remove(0);
                    }
                    cell
                }
            }
        };
        let mut built = false;
        let r = cell
            .get_or_init(|| {
                built = true;
                make().map(Arc::new)
            })
            .clone();
        (r, !built)
    }
}

pub(super) fn geometry_key(s: &FeSetup) -> String {
    format!(
        "{:?}|{:e}|{:e}|{:e}",
        s.geometry, s.density, s.lame_lambda, s.lame_mu
    )
}
