//! The energy ledger of a run with heat transfer: what the particles and the gas hold, what the heated walls and
//! the gas's boundary gave them, and the latent heat the evaporated liquid took away, so that a run can show its
//! energy closes at every series row (issue 38: "energy closed, latent heat counted").
//!
//! E_now = Σ m c_p T (particles) + Σ ε ρ c_g T V (gas) + c_g V Δt_DEM Σ (convection gathered for the next gas step)
//!         + L × (liquid evaporated, net of condensation)
//! E_expected = E_start + (heat from walls into particles) + (heat into the gas across its boundary: walls held at a
//!         temperature, inlets, outlets) + (the gas temperature equation's continuity term, below)
//!
//! and the closure is E_now / E_expected − 1. The gas temperature is solved in Patankar's form
//! (`gas/scalar.rs`), whose content changes by the boundary flows plus Σ r_P T_P, r_P the cell's continuity residual
//! left by the pressure–velocity solve: that term is tallied on its own (`gas_continuity_j`), so the ledger shows how
//! much energy the form creates or destroys rather than hiding it. Closure is limited by the gas temperature's linear
//! solve (relative residual `gas.solver.linear_tolerance`, 1e-8 by default) acting on the gas's small share of the
//! energy.
//!
//! The wall heat into the particles is summed in fixed point ([`FixedPointSum`]) so the sum is the same bits
//! whatever the thread count splits the particles into: the ledger is checkpointed and a restart on other threads
//! must reproduce it.

/// The ledger's running totals, J. Part of the state (checkpointed under `heat_ledger/`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HeatLedger {
    /// Particles' and gas's thermal energy at the start (latent heat counted from zero then), J.
    pub initial_energy_j: f64,
    /// Heat conducted from walls held at a temperature into particles (contacts, gas lenses, liquid bridges), J.
    pub wall_to_particles_j: f64,
    /// Heat that entered the gas across its boundary (walls held at a temperature, inlets), J.
    pub gas_boundary_in_j: f64,
    /// Heat that left the gas across its boundary (outlets, colder walls), J.
    pub gas_boundary_out_j: f64,
    /// The gas temperature equation's continuity term c_g Σ r_P T_P Δt (see the module documentation), J.
    pub gas_continuity_j: f64,
}

impl HeatLedger {
    /// The energy the run should hold now: the start plus all that crossed into it, J.
    pub fn expected_energy_j(&self) -> f64 {
        self.initial_energy_j + self.wall_to_particles_j + self.gas_boundary_in_j - self.gas_boundary_out_j
            + self.gas_continuity_j
    }
}

/// An order-independent sum of f64 values: each is rounded to a multiple of 2^-SCALE_BITS and the integers are
/// added, so any grouping (threads) gives the same bits. With SCALE_BITS = 80 a sum holds up to 2^46 (7e13) in
/// magnitude at a resolution of 8e-25; a value beyond that range saturates (and shows as a failed ledger).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FixedPointSum(i128);

impl FixedPointSum {
    const SCALE_BITS: i32 = 80;

    pub fn add(&mut self, value: f64) {
        // `as` saturates and maps NaN to 0; the rounding of one value is fixed, whatever the order of additions.
        self.0 = self
            .0
            .saturating_add((value * 2f64.powi(Self::SCALE_BITS)).round() as i128);
    }

    pub fn merge(&mut self, other: FixedPointSum) {
        self.0 = self.0.saturating_add(other.0);
    }

    pub fn value(&self) -> f64 {
        self.0 as f64 * 2f64.powi(-Self::SCALE_BITS)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fixed_point_sum_does_not_depend_on_the_grouping() {
        let values: Vec<f64> = (0..1000)
            .map(|k| ((k as f64) * 0.737).sin() * 10f64.powi(k % 7 - 4))
            .collect();
        let mut serial = FixedPointSum::default();
        values.iter().for_each(|&v| serial.add(v));
        let mut grouped = FixedPointSum::default();
        for chunk in values.chunks(37).rev() {
            let mut part = FixedPointSum::default();
            chunk.iter().rev().for_each(|&v| part.add(v));
            grouped.merge(part);
        }
        assert_eq!(serial, grouped);
        let plain: f64 = values.iter().sum();
        assert!((serial.value() - plain).abs() <= 1e-12 * plain.abs().max(1.0));
    }
}
