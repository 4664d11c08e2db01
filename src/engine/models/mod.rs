//! Contact models: each slot is a closed enum of named variants with typed parameters and pure kernels, tested
//! beside them. Cohesion, liquid bridges, drag, heat and mass transfer join here in later issues.

pub mod bridge_conduction;
pub mod capillary;
pub mod capillary_cache;
pub mod capillary_table;
pub mod cohesion;
pub mod cohesion_law;
pub mod conduction;
pub mod contact_law;
pub mod convection;
pub mod drag;
pub mod evaporation;
pub mod gas_lens;
pub mod history;
pub mod liquid_transfer;
pub mod normal;
pub mod pair_table;
pub mod rolling;
pub mod tangential;
pub mod young_laplace;

pub use contact_law::{ContactKinematics, ContactLaw, ContactOutput};
pub use history::ContactHistory;
pub use normal::{NormalModel, PlasticSlope};
pub use pair_table::{PairMaterial, PairTable};
pub use rolling::RollingModel;
pub use tangential::TangentialModel;
