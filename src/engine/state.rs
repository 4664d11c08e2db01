//! `SimState`: everything a checkpoint holds, and nothing that can be rebuilt (neighbour lists, buffers, timers).
//!
//! Restoring a `SimState` into a `Simulation` with the same configuration continues the run bit for bit.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;

use super::contacts::ContactStore;
use super::particles::Particles;

/// The complete state of a ChaCha8 generator: seed, stream and position.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RngState {
    pub seed: [u8; 32],
    pub stream: u64,
    pub word_pos: u128,
}

impl RngState {
    /// A generator seeded from a 64-bit seed (e.g. derived from the campaign seed and job id).
    pub fn from_seed_u64(seed: u64) -> Self {
        let rng = ChaCha8Rng::seed_from_u64(seed);
        RngState::capture(&rng)
    }

    pub fn capture(rng: &ChaCha8Rng) -> Self {
        RngState {
            seed: rng.get_seed(),
            stream: rng.get_stream(),
            word_pos: rng.get_word_pos(),
        }
    }

    pub fn restore(&self) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::from_seed(self.seed);
        rng.set_stream(self.stream);
        rng.set_word_pos(self.word_pos);
        rng
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct SimState {
    pub step: u64,
    pub time_s: f64,
    pub dt_s: f64,
    pub particles: Particles,
    /// Angle turned by each wall (0 for static walls), rad.
    pub wall_angle_rad: Vec<f64>,
    pub contacts: ContactStore,
    pub rng: RngState,
}
