//! Criterion benchmarks of the per-contact kernels (one loaded contact evaluated repeatedly), per contact law.
//! Run: `cargo bench --bench contact_kernels`.

use criterion::{Criterion, criterion_group, criterion_main};
use granflow::engine::Vec3;
use granflow::engine::models::{
    ContactHistory, ContactKinematics, ContactLaw, NormalModel, PairMaterial, PlasticSlope, RollingModel,
    TangentialModel,
};
use std::hint::black_box;

fn kernels(c: &mut Criterion) {
    let mat = PairMaterial {
        effective_youngs_modulus_pa: 1e7 / (2.0 * (1.0 - 0.33f64.powi(2))),
        effective_shear_modulus_pa: 1e7 / (4.0 * (2.0 - 0.33) * 1.33),
        friction_coefficient: 0.3,
        yield_force_n: 0.05,
        rolling_friction_coefficient: 0.0,
        hertz_damping_factor_pa: 0.0,
        tangential_damping_ratio: 1.0,
    };
    let k = ContactKinematics {
        normal: Vec3::new(0.0, 0.6, 0.8),
        overlap_m: 1e-5,
        effective_radius_m: 7.5e-4,
        effective_mass_kg: 1.77e-5,
        contact_velocity: Vec3::new(0.01, -0.02, 0.003),
        // contact_velocity · normal
        normal_velocity_m_per_s: -0.0096,
        relative_angular_velocity: Vec3::new(0.1, 0.2, -0.3),
    };
    let laws = [
        (
            "hertz_mindlin",
            ContactLaw {
                normal: NormalModel::Hertz { restitution: 0.9 },
                tangential: TangentialModel::Mindlin,
                rolling: RollingModel::None,
            },
        ),
        (
            "thornton_walton_braun",
            ContactLaw {
                normal: NormalModel::Thornton {
                    plastic_slope: PlasticSlope::Continuous,
                },
                tangential: TangentialModel::WaltonBraun { exponent: 1.0 / 3.0 },
                rolling: RollingModel::None,
            },
        ),
        (
            "linear_coulomb",
            ContactLaw {
                normal: NormalModel::LinearSpringDashpot {
                    stiffness_n_per_m: 800.0,
                    damping_kg_per_s: 7.9e-4,
                },
                tangential: TangentialModel::LinearSpringCoulomb {
                    stiffness_n_per_m: 800.0,
                    damping_kg_per_s: 7.9e-4,
                },
                rolling: RollingModel::None,
            },
        ),
    ];
    for (name, law) in laws {
        c.bench_function(&format!("contact/{name}"), |b| {
            let mut h = ContactHistory::default();
            b.iter(|| black_box(law.evaluate(black_box(&mat), black_box(&k), 1e-5, &mut h)))
        });
    }
}

criterion_group!(benches, kernels);
criterion_main!(benches);
