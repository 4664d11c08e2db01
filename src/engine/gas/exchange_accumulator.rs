//! What the particles exchange with the gas over the DEM sub-steps of one gas step, gathered per slot of the gas
//! grid (a cell for a cell-centred scalar, a face for one velocity component) until the gas takes its step.
//!
//! An exchange between a particle at value φ_p and the gas at φ has the form k (φ_p − φ) (drag: k = K, φ = u;
//! heat: k = h A, φ = T). Each sub-step adds, at each slot the particle touches, its share of
//! - the coefficient k (Σk),
//! - the coefficient times the particle's value (Σk·φ_p),
//! - the amount the particle actually received under the frozen gas field (the transfer, for an explicit coupling
//!   that hands the gas exactly what the particles lost).
//!
//! The gas step uses the means over the sub-steps: explicitly, the mean transfer as a source; implicitly, the
//! source Σk(φ_p − φ) linearised as a_P += Σk, b += Σk·φ_p (Patankar 1980 §4.2-7, a negative S_P). The sums are
//! plain additions in the caller's order, so a caller that adds in a fixed order gets the same bits on every run.
//! Which particle model fills which slots, and with what weights, is the caller's; this holds only the sums.

/// Sums over the DEM sub-steps since the last gas step, one entry per slot.
#[derive(Debug, Clone, PartialEq)]
pub struct ExchangeAccumulator {
    /// Σ over sub-steps of the exchange coefficient k at each slot (per unit volume; its unit is the caller's).
    pub coefficient_sum: Vec<f64>,
    /// Σ over sub-steps of k·φ_p, with φ_p the particle value the exchange used.
    pub coefficient_value_sum: Vec<f64>,
    /// Σ over sub-steps of what the gas received, as the particles computed it (the explicit form).
    pub transfer_sum: Vec<f64>,
    /// Sub-steps accumulated since the last [`Self::clear`].
    pub steps: u32,
}

impl ExchangeAccumulator {
    /// Empty sums over `slots` slots.
    pub fn new(slots: usize) -> Self {
        ExchangeAccumulator {
            coefficient_sum: vec![0.0; slots],
            coefficient_value_sum: vec![0.0; slots],
            transfer_sum: vec![0.0; slots],
            steps: 0,
        }
    }

    /// Adds a share `coefficient` of an exchange with a particle at `particle_value` to `slot`.
    #[inline]
    pub fn add_exchange(&mut self, slot: usize, coefficient: f64, particle_value: f64) {
        self.coefficient_sum[slot] += coefficient;
        self.coefficient_value_sum[slot] += coefficient * particle_value;
    }

    /// Adds sums over several sub-steps at once: Σk and Σk·φ_p of one particle's share of `slot` (an exchange
    /// held over the sub-steps and spread once).
    #[inline]
    pub fn add_exchange_sums(&mut self, slot: usize, coefficient_sum: f64, coefficient_value_sum: f64) {
        self.coefficient_sum[slot] += coefficient_sum;
        self.coefficient_value_sum[slot] += coefficient_value_sum;
    }

    /// Adds `amount` received by the gas at `slot` (explicit form).
    #[inline]
    pub fn add_transfer(&mut self, slot: usize, amount: f64) {
        self.transfer_sum[slot] += amount;
    }

    /// Closes one sub-step: the means divide by the number of closed sub-steps.
    pub fn end_sub_step(&mut self) {
        self.steps += 1;
    }

    /// Zeroes the sums and the sub-step count (a new gas field is frozen).
    pub fn clear(&mut self) {
        for sum in [
            &mut self.transfer_sum,
            &mut self.coefficient_sum,
            &mut self.coefficient_value_sum,
        ] {
            sum.iter_mut().for_each(|v| *v = 0.0);
        }
        self.steps = 0;
    }

    /// Mean Σk per sub-step at each slot (the sums themselves before the first sub-step closes).
    pub fn mean_coefficient(&self) -> Vec<f64> {
        self.mean(&self.coefficient_sum)
    }

    /// Mean Σk·φ_p per sub-step at each slot.
    pub fn mean_coefficient_value(&self) -> Vec<f64> {
        self.mean(&self.coefficient_value_sum)
    }

    /// Mean transfer per sub-step at each slot.
    pub fn mean_transfer(&self) -> Vec<f64> {
        self.mean(&self.transfer_sum)
    }

    fn mean(&self, sum: &[f64]) -> Vec<f64> {
        let n = f64::from(self.steps.max(1));
        sum.iter().map(|v| v / n).collect()
    }

    /// Puts checkpointed sums back; the slot counts must match.
    pub fn restore(
        &mut self,
        coefficient_sum: &[f64],
        coefficient_value_sum: &[f64],
        transfer_sum: &[f64],
        steps: u32,
    ) -> Result<(), String> {
        let slots = self.coefficient_sum.len();
        for (what, given) in [
            ("coefficient sum", coefficient_sum.len()),
            ("coefficient-value sum", coefficient_value_sum.len()),
            ("transfer sum", transfer_sum.len()),
        ] {
            if given != slots {
                return Err(format!("exchange {what}: expected {slots} values, got {given}"));
            }
        }
        self.coefficient_sum.copy_from_slice(coefficient_sum);
        self.coefficient_value_sum.copy_from_slice(coefficient_value_sum);
        self.transfer_sum.copy_from_slice(transfer_sum);
        self.steps = steps;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::ExchangeAccumulator;

    #[test]
    fn means_are_the_sums_over_the_closed_sub_steps() {
        let mut acc = ExchangeAccumulator::new(3);
        // Two sub-steps; slot 1 sees a particle at φ_p = 2 with k = 4, then one at φ_p = 5 with k = 1.
        acc.add_exchange(1, 4.0, 2.0);
        acc.add_transfer(1, -0.5);
        acc.end_sub_step();
        acc.add_exchange(1, 1.0, 5.0);
        acc.add_transfer(1, -1.5);
        acc.end_sub_step();
        assert_eq!(acc.mean_coefficient(), vec![0.0, 2.5, 0.0]);
        assert_eq!(acc.mean_coefficient_value(), vec![0.0, 6.5, 0.0]);
        assert_eq!(acc.mean_transfer(), vec![0.0, -1.0, 0.0]);
        // The linearised source Σk(φ_p − φ) vanishes at the coefficient-weighted particle value 13/5.
        let (k, kv) = (acc.mean_coefficient()[1], acc.mean_coefficient_value()[1]);
        assert_eq!(kv - k * (13.0 / 5.0), 0.0);
        acc.clear();
        assert_eq!(acc, ExchangeAccumulator::new(3));
    }

    #[test]
    fn before_any_closed_sub_step_the_mean_is_the_sum() {
        let mut acc = ExchangeAccumulator::new(1);
        acc.add_exchange(0, 3.0, 1.0);
        assert_eq!(acc.mean_coefficient(), vec![3.0]);
    }

    #[test]
    fn restore_refuses_a_different_slot_count() {
        let mut acc = ExchangeAccumulator::new(2);
        let err = acc.restore(&[1.0, 2.0], &[1.0], &[0.0, 0.0], 3).unwrap_err();
        assert!(err.contains("coefficient-value sum"), "{err}");
        acc.restore(&[1.0, 2.0], &[3.0, 4.0], &[5.0, 6.0], 3).unwrap();
        assert_eq!(acc.mean_transfer(), vec![5.0 / 3.0, 2.0]);
    }
}
