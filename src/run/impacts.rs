//! Contact phases detected online, step by step, at full time resolution (issue 12).
//!
//! # Rule
//! A step is in contact when σ_C < 0 (every scene stores σ_C ≤ 0 in contact; 2D/3D: minus the
//! total contact force). A *contact phase* is a maximal run of contact steps in which a gap of
//! at most [`MERGE_GAP`] step without pressure does not end the phase: the step-to-step
//! alternation of the pressure (Nitsche-Hybrid's σ_C^n alternates between 0 and about three
//! times the exact value while the node stays on the obstacle) is not a lift-off. This is the
//! rule the summary applies to a stored series (`summary::energy`), here applied to every
//! step, whatever `series_every` keeps: phase ends are exact steps, never a recording stride.
//!
//! # What a phase records
//! First and last contact step n_f, n_l and their times, and the energy E and augmented energy
//! E_Θ at the step just before the phase (n_f − 1) and just after it (n_l + 1) — None where
//! that step is outside the run (a phase open at step 0, or still open at the last step).
//! The energy lost by an impact is (E^{n_f−1} − E^{n_l+1})/E⁰.
//!
//! # Why online
//! The summary used to read back and decode the whole `series/` folder (1.5 M rows for a
//! 400-run 1D sweep) only to find these phases; a run knows them for the cost of a comparison
//! per step, and they travel with the run's row, committed atomically with it.
//!
//! # Pressure oscillation (contract §3.2)
//! Per contact interval, TV/(2·max|σ_C|) with TV the total variation of σ_C over the
//! interval's steps, the rise from zero before its first step and the fall to zero after its
//! last included: 1 for a pressure that rises once and falls once (any monotone rise and fall),
//! 1 + (the chatter's variation)/(2·peak) otherwise. The run's `pressure_oscillation` is the
//! largest over its intervals (None without contact). The intervals here are the maximal runs
//! of consecutive steps with σ_C < 0 — *not* the phases above, whose one-step gaps merge: contract
//! §6's figures are those of unmerged intervals (Moreau–Jean with e = 1 applies its impulses
//! every other step through an impact, each one an interval of one step: 1.00; merged, the
//! same run would read 30). Accumulated at every step: a decimated series would miss it.
//!
//! # Memory
//! The phase list is reserved at setup for [`RESERVED_PHASES`] phases, so the time loop does
//! not allocate (tests/alloc.rs). A run with more phases (a chattering contact) grows the list
//! by doubling: amortised O(1) per phase and log₂(phases/256) allocations in the whole run,
//! never one per step.

/// Steps without pressure that do not end a contact phase (one: a pressure alternating step
/// by step; two steps without pressure already count as a lift-off).
pub const MERGE_GAP: usize = 1;

/// Phases reserved at setup (48 bytes each: 12 kB per run in flight).
pub const RESERVED_PHASES: usize = 256;

/// One contact phase of a run.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Phase {
    pub step_first: i64,
    pub step_last: i64,
    pub t_first: f64,
    pub t_last: f64,
    pub energy_before: Option<f64>,
    pub energy_after: Option<f64>,
    pub energy_theta_before: Option<f64>,
    pub energy_theta_after: Option<f64>,
}

/// The values of the previous step that a phase opening now needs.
#[derive(Debug, Clone, Copy)]
struct Prev {
    energy: f64,
    theta: Option<f64>,
}

/// Detects contact phases as the steps arrive.
#[derive(Debug)]
pub struct PhaseTracker {
    phases: Vec<Phase>,
    /// The phase still open (not yet followed by MERGE_GAP + 1 steps without pressure).
    open: Option<Phase>,
    prev: Option<Prev>,
    /// The first step after the open phase's last contact step was observed (its values are
    /// in `open.energy_after`): the phase's `after` if no contact follows within the gap.
    after_seen: bool,
    /// The open contact interval (σ < 0 at every step of it): total variation of σ so far
    /// (the rise from zero included), its peak |σ| and σ at the previous step.
    in_interval: bool,
    tv: f64,
    peak: f64,
    sigma_prev: f64,
    /// Largest TV/(2·peak) of the closed intervals.
    oscillation: Option<f64>,
}

impl Default for PhaseTracker {
    fn default() -> Self {
        Self::new()
    }
}

impl PhaseTracker {
    pub fn new() -> Self {
        Self {
            phases: Vec::with_capacity(RESERVED_PHASES),
            open: None,
            prev: None,
            after_seen: false,
            in_interval: false,
            tv: 0.0,
            peak: 0.0,
            sigma_prev: 0.0,
            oscillation: None,
        }
    }

    /// Follow the contact intervals of σ (module header, pressure oscillation).
    #[inline]
    fn track_oscillation(&mut self, sigma: f64) {
        if sigma < 0.0 {
            if self.in_interval {
                self.tv += (sigma - self.sigma_prev).abs();
                self.peak = self.peak.max(-sigma);
            } else {
                // The rise from zero.
                self.in_interval = true;
                self.tv = -sigma;
                self.peak = -sigma;
            }
        } else if self.in_interval {
            self.close_oscillation();
        }
        self.sigma_prev = sigma;
    }

    /// Close the open interval: TV with the fall to zero from its last step, over twice the
    /// peak.
    fn close_oscillation(&mut self) {
        if !self.in_interval {
            return;
        }
        self.in_interval = false;
        let r = (self.tv + self.sigma_prev.abs()) / (2.0 * self.peak);
        self.oscillation = Some(self.oscillation.map_or(r, |o| o.max(r)));
    }

    /// max over the contact intervals closed so far (all of them after [`Self::finish`]) of
    /// TV(σ)/(2·max|σ|); None if there was none.
    pub fn pressure_oscillation(&self) -> Option<f64> {
        self.oscillation
    }

    /// Record step `step` (consecutive steps, from the first observed one).
    #[inline]
    pub fn step(&mut self, step: usize, t: f64, sigma: f64, energy: f64, theta: Option<f64>) {
        let contact = sigma < 0.0;
        let step = step as i64;
        match &mut self.open {
            None => {
                if contact {
                    self.open = Some(Phase {
                        step_first: step,
                        step_last: step,
                        t_first: t,
                        t_last: t,
                        energy_before: self.prev.map(|p| p.energy),
                        energy_theta_before: self.prev.and_then(|p| p.theta),
                        energy_after: None,
                        energy_theta_after: None,
                    });
                    self.after_seen = false;
                }
            }
            Some(ph) => {
                if contact {
                    ph.step_last = step;
                    ph.t_last = t;
                    ph.energy_after = None;
                    ph.energy_theta_after = None;
                    self.after_seen = false;
                } else if step - ph.step_last == 1 {
                    // Candidate `after`: kept if the gap does not close.
                    ph.energy_after = Some(energy);
                    ph.energy_theta_after = theta;
                    self.after_seen = true;
                } else if step - ph.step_last > MERGE_GAP as i64 {
                    let done = *ph;
                    // Within the reserve: no allocation (see the module header beyond it).
                    self.phases.push(done);
                    self.open = None;
                    self.after_seen = false;
                }
            }
        }
        self.track_oscillation(sigma);
        self.prev = Some(Prev { energy, theta });
    }

    /// The phases of the run, the open one closed (its `after` is the step after its last
    /// contact step if the run reached it, else None). Moves the list out (no copy, no
    /// allocation within the reserve); the tracker is empty afterwards.
    pub fn finish(&mut self) -> Vec<Phase> {
        let mut out = std::mem::take(&mut self.phases);
        self.close_oscillation();
        if let Some(mut ph) = self.open.take() {
            if !self.after_seen {
                ph.energy_after = None;
                ph.energy_theta_after = None;
            }
            out.push(ph);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feed σ values at steps 0, 1, …; energy = 10 + step, E_Θ = 100 + step so that the
    /// recorded before/after values name their step.
    fn run(sigma: &[f64]) -> Vec<Phase> {
        let mut p = PhaseTracker::new();
        for (n, &s) in sigma.iter().enumerate() {
            p.step(
                n,
                0.5 * n as f64,
                s,
                10.0 + n as f64,
                Some(100.0 + n as f64),
            );
        }
        p.finish()
    }

    #[test]
    fn one_step_gaps_merge_and_two_step_gaps_split() {
        // steps: 0 1 2 3 4 5 6 7 8 9
        let s = [0.0, -1.0, 0.0, -1.0, 0.0, 0.0, -2.0, -1.0, 0.0, 0.0];
        let ph = run(&s);
        assert_eq!(ph.len(), 2);
        assert_eq!((ph[0].step_first, ph[0].step_last), (1, 3));
        assert_eq!((ph[0].t_first, ph[0].t_last), (0.5, 1.5));
        assert_eq!(ph[0].energy_before, Some(10.0)); // step 0
        assert_eq!(ph[0].energy_after, Some(14.0)); // step 4
        assert_eq!(ph[0].energy_theta_after, Some(104.0));
        assert_eq!((ph[1].step_first, ph[1].step_last), (6, 7));
        assert_eq!(ph[1].energy_before, Some(15.0));
        assert_eq!(ph[1].energy_after, Some(18.0));
    }

    #[test]
    fn phases_at_the_run_ends_have_no_outside_step() {
        // In contact from step 0; in contact at the last step.
        let ph = run(&[-1.0, -1.0, 0.0, 0.0, 0.0, -1.0]);
        assert_eq!(ph.len(), 2);
        assert_eq!(ph[0].energy_before, None);
        assert_eq!(ph[0].energy_after, Some(12.0));
        assert_eq!(ph[1].step_first, 5);
        assert_eq!(ph[1].energy_before, Some(14.0));
        assert_eq!(ph[1].energy_after, None);
        // Open phase whose gap step is the last step: that step is its `after`.
        let ph = run(&[0.0, -1.0, 0.0]);
        assert_eq!((ph[0].step_last, ph[0].energy_after), (1, Some(12.0)));
    }

    fn oscillation(sigma: &[f64]) -> Option<f64> {
        let mut p = PhaseTracker::new();
        for (n, &s) in sigma.iter().enumerate() {
            p.step(n, n as f64, s, 1.0, None);
        }
        p.finish();
        p.pressure_oscillation()
    }

    #[test]
    fn pressure_oscillation_is_one_for_a_single_rise_and_fall() {
        // Rise 0 → −1 → −2, hold, fall: TV = 4 = 2·peak (binary values: exact).
        assert_eq!(
            oscillation(&[0.0, -1.0, -2.0, -2.0, -1.0, 0.0, 0.0]),
            Some(1.0)
        );
        // Alternating between two levels: TV = 1 + 3·1 + 2 = 6 over 2·2 → 1.5; the worse of two
        // intervals wins. A one-step gap ends an interval (unlike a phase): pulses read 1 each.
        assert_eq!(
            oscillation(&[0.0, -1.0, -2.0, -1.0, -2.0, 0.0, 0.0, -3.0, 0.0, 0.0]),
            Some(1.5)
        );
        assert_eq!(
            oscillation(&[0.0, -1.0, 0.0, -1.0, 0.0, -1.0, 0.0]),
            Some(1.0)
        );
        // A phase still open at the end falls to zero by definition; no contact: None.
        assert_eq!(oscillation(&[0.0, -2.0, -1.0]), Some(1.0));
        assert_eq!(oscillation(&[0.0, 0.0]), None);
    }

    #[test]
    fn more_phases_than_reserved_are_all_kept() {
        let s: Vec<f64> = (0..3 * (RESERVED_PHASES + 10))
            .map(|n| if n % 3 == 0 { -1.0 } else { 0.0 })
            .collect();
        assert_eq!(run(&s).len(), RESERVED_PHASES + 10);
    }
}
