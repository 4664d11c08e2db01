//! VALIDATION C5 (a single particle settling in gas reaches the terminal velocity its drag law implies) through the
//! coupled gas–particle simulation, and Newton's third law between particles and gas.

mod common;

use common::{built, simulation};
use granflow::engine::Simulation;
use granflow::engine::Vec3;
use granflow::engine::gas::coupled::GasCoupling;
use granflow::engine::gas::coupling::{PorosityMethod, gas_velocity_at};
use granflow::engine::gas::fluid_forces::DragVelocities;
use granflow::engine::gas::{Boundary, Convection, GasConfig, Grid};
use granflow::engine::models::drag::{DragInput, DragLaw};

const RADIUS: f64 = 0.00025;
const DENSITY: f64 = 1000.0;

fn settling(threads: usize) -> Simulation {
    // A periodic box (particles and gas): the particle falls for ever through quiescent air.
    let yaml = format!(
        r#"
name: settling-sphere
domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.009, 0.009, 0.03], periodic: [true, true, true] }}
gravity: {{ vector_m_per_s2: [0.0, 0.0, -9.81] }}
species:
  - {{ name: bead, radius_m: {RADIUS}, density_kg_per_m3: {DENSITY}, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3 }}
contact: {{ normal: {{ hertz: {{ restitution: 0.9 }} }}, tangential: mindlin }}
fill:
  - explicit: {{ species: bead, positions_m: [[0.0041, 0.0043, 0.02]] }}
time: {{ dt_s: 1.0e-4, end_time_s: 2.0 }}
"#
    );
    let b = built(&yaml);
    let dem = simulation(&b, threads);
    let grid = Grid {
        n: [6, 6, 20],
        h_m: [0.0015, 0.0015, 0.0015],
        origin_m: [0.0; 3],
        boundary: [Boundary::Periodic; 6],
    };
    let gas = GasConfig {
        grid,
        density_kg_per_m3: 1.2,
        viscosity_pa_s: 1.8e-5,
        // The weight of the gas is not simulated in a periodic box (it would accelerate for ever); the particle
        // then feels no buoyancy, and its terminal slip satisfies K(w) w = m g.
        gravity_m_per_s2: [0.0; 3],
        convection: Convection::Hybrid,
        relax_velocity: 0.8,
        relax_pressure: 0.5,
        max_outer_iterations: 20,
        mass_tolerance: 1e-8,
        velocity_tolerance: 1e-6,
        linear_tolerance: 1e-10,
        max_linear_iterations: 1000,
        pressure_solver: Default::default(),
        pressure_velocity: Default::default(),
        inlet_faces: Vec::new(),
        inflow_ramp: None,
        inflow_levels: None,
        blocked: Vec::new(),
        blocked_wall_motion: None,
        pressure_reference_cell: None,
    };
    let mass = dem.particles.mass_kg[0];
    let mut dem = dem;
    let p = &dem.particles;
    let mut coupling = GasCoupling::new(
        gas,
        DragLaw::DiFelice,
        DragVelocities::Instantaneous,
        PorosityMethod::VolumeSplit,
        0.3,
        20,
        &p.position_m,
        &p.radius_m,
    )
    .unwrap();
    // The mean pressure gradient of a periodic suspension carries the particle's weight: without it the gas and
    // particle together would accelerate downwards.
    coupling.gas_body_force_n_per_m3 = [0.0, 0.0, mass * 9.81 / (0.009 * 0.009 * 0.03)];
    dem.attach_gas(coupling);
    dem
}

#[test]
fn c5_single_particle_reaches_the_terminal_velocity_of_its_drag_law() {
    let mut sim = settling(1);
    for _ in 0..750 {
        sim.run_steps(20).unwrap();
    }
    let p = &sim.particles;
    let fluid = &sim.gas.as_ref().unwrap().fluid;
    let u = gas_velocity_at(&fluid.grid, &fluid.velocity_m_per_s, &p.position_m[0]);
    let slip = (u - p.velocity_m_per_s[0]).z;
    // The porosity the drag law saw: the particle's cell.
    let x = p.position_m[0];
    let cell = fluid.grid.cell(std::array::from_fn(|a| {
        ((x[a] / fluid.grid.h_m[a]).floor() as usize) % fluid.grid.n[a]
    }));
    let eps = fluid.porosity[cell];
    let mass = p.mass_kg[0];
    let drag = |w: f64| {
        DragLaw::DiFelice.coefficient_n_s_per_m(&DragInput {
            porosity: eps,
            slip_speed_m_per_s: w,
            diameter_m: 2.0 * RADIUS,
            gas_density_kg_per_m3: 1.2,
            gas_viscosity_pa_s: 1.8e-5,
        }) * w
    };
    // Bisection for K(w) w = m g.
    let (mut lo, mut hi) = (0.0, 100.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if drag(mid) < mass * 9.81 { lo = mid } else { hi = mid }
    }
    let terminal = 0.5 * (lo + hi);
    let error = slip / terminal - 1.0;
    eprintln!(
        "C5: slip {slip:.5} m/s, terminal {terminal:.5} m/s ({:+.3} %), particle {:.4} m/s, gas at particle {:.4} m/s, ε {eps:.5}",
        100.0 * error,
        p.velocity_m_per_s[0].z,
        u.z
    );
    assert!(error.abs() < 0.01, "{:+.3} %", 100.0 * error);
}

#[test]
fn the_gas_receives_exactly_the_momentum_the_particle_loses_to_drag() {
    let mut sim = settling(1);
    for _ in 0..20 {
        sim.run_steps(20).unwrap();
    }
    let mut fluid = sim.gas.as_ref().unwrap().fluid.clone();
    fluid.momentum_exchange.iter_mut().for_each(|e| e.clear());
    // Drag only: the pressure-gradient force is not returned to the gas (model A).
    fluid
        .minus_pressure_gradient_pa_per_m
        .iter_mut()
        .for_each(|r| r.iter_mut().for_each(|v| *v = 0.0));
    let p = &sim.particles;
    let mut force = vec![Vec3::zeros(); 1];
    fluid.add_forces(&p.position_m, &p.velocity_m_per_s, &p.radius_m, &mut force, None);
    let volume = fluid.grid.cell_volume_m3();
    for a in 0..3 {
        let given: f64 = fluid.momentum_exchange[a].transfer_sum.iter().sum::<f64>() * volume;
        assert!(
            (given + force[0][a]).abs() <= 1e-12 * force[0].norm().max(1e-30),
            "axis {a}: {given} vs {}",
            force[0][a]
        );
    }
}

#[test]
fn coupled_runs_are_bit_identical_on_one_and_two_threads() {
    let mut one = settling(1);
    let mut two = settling(2);
    for _ in 0..30 {
        one.run_steps(20).unwrap();
        two.run_steps(20).unwrap();
    }
    let bits = |v: &Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
    assert_eq!(bits(&one.particles.position_m[0]), bits(&two.particles.position_m[0]));
    assert_eq!(
        bits(&one.particles.velocity_m_per_s[0]),
        bits(&two.particles.velocity_m_per_s[0])
    );
    for a in 0..3 {
        let ua: Vec<u64> = one.gas.as_ref().unwrap().solver.state.velocity_m_per_s[a]
            .iter()
            .map(|v| v.to_bits())
            .collect();
        let ub: Vec<u64> = two.gas.as_ref().unwrap().solver.state.velocity_m_per_s[a]
            .iter()
            .map(|v| v.to_bits())
            .collect();
        assert_eq!(ua, ub);
    }
}

#[test]
fn cell_averaged_drag_gives_the_gas_exactly_what_the_particles_get() {
    // Seed 002's method 1 with several particles in the same and in neighbouring cells.
    let sim = settling(1);
    let mut fluid = sim.gas.as_ref().unwrap().fluid.clone();
    fluid.drag_velocities = DragVelocities::CellAveraged;
    fluid
        .minus_pressure_gradient_pa_per_m
        .iter_mut()
        .for_each(|r| r.iter_mut().for_each(|v| *v = 0.0));
    // A gas field with a shear, so the cell-centre velocities differ.
    for a in 0..3 {
        for (f, v) in fluid.velocity_m_per_s[a].iter_mut().enumerate() {
            *v = 0.01 * (f % 7) as f64 - 0.02 * a as f64;
        }
    }
    let positions: Vec<Vec3> = (0..9)
        .map(|k| {
            Vec3::new(
                0.0005 + 0.0011 * k as f64,
                0.004 + 0.0003 * (k % 3) as f64,
                0.01 + 0.002 * (k % 4) as f64,
            )
        })
        .collect();
    let velocities: Vec<Vec3> = (0..9)
        .map(|k| Vec3::new(0.1 * k as f64, -0.05, 0.02 * (k % 2) as f64))
        .collect();
    let radii = vec![RADIUS; 9];
    let mut force = vec![Vec3::zeros(); 9];
    fluid.add_forces(&positions, &velocities, &radii, &mut force, None);
    let volume = fluid.grid.cell_volume_m3();
    let total: Vec3 = force.iter().sum();
    for a in 0..3 {
        let given: f64 = fluid.momentum_exchange[a].transfer_sum.iter().sum::<f64>() * volume;
        assert!(
            (given + total[a]).abs() <= 1e-12 * total.norm(),
            "axis {a}: {given} vs {}",
            total[a]
        );
    }
    // The drag of a particle does not depend on where in its cell it sits (particle 0 moved within its cell).
    let mut shifted = positions.clone();
    shifted[0].x += 0.0003;
    let mut fluid2 = fluid.clone();
    let mut force2 = vec![Vec3::zeros(); 9];
    fluid2.add_forces(&shifted, &velocities, &radii, &mut force2, None);
    assert_eq!(
        force[0], force2[0],
        "cell-averaged drag does not depend on the position inside the cell"
    );
}

#[test]
fn fluid_forces_on_a_team_give_the_same_bits_as_on_one_thread() {
    let sim = settling(1);
    let team = granflow::engine::team::Team::new(2);
    use granflow::engine::gas::held_drag::DragUpdate;
    let choices = [DragVelocities::Instantaneous, DragVelocities::CellAveraged]
        .into_iter()
        .flat_map(|v| [(v, DragUpdate::EveryDemStep), (v, DragUpdate::EveryGasStep)]);
    for (method, update) in choices {
        let mut serial = sim.gas.as_ref().unwrap().fluid.clone();
        serial.drag_velocities = method;
        serial.drag_update = update;
        for a in 0..3 {
            for (f, v) in serial.velocity_m_per_s[a].iter_mut().enumerate() {
                *v = 0.013 * (f % 5) as f64 - 0.01 * a as f64;
            }
            for (f, g) in serial.minus_pressure_gradient_pa_per_m[a].iter_mut().enumerate() {
                *g = 3.0 * (f % 3) as f64;
            }
        }
        let mut parallel = serial.clone();
        // Enough particles for several parallel chunks.
        let n = 3000;
        let positions: Vec<Vec3> = (0..n)
            .map(|k| {
                let t = k as f64;
                Vec3::new((t * 0.000_37) % 0.009, (t * 0.000_53) % 0.009, (t * 0.000_11) % 0.03)
            })
            .collect();
        let velocities: Vec<Vec3> = (0..n)
            .map(|k| Vec3::new(0.001 * (k % 7) as f64, -0.02, 0.003))
            .collect();
        let radii = vec![RADIUS; n];
        let (mut f1, mut f2) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
        serial.add_forces(&positions, &velocities, &radii, &mut f1, None);
        parallel.add_forces(&positions, &velocities, &radii, &mut f2, Some(&team));
        // A second sub-step (held drag: from the held values), then the reaction settled.
        serial.add_forces(&positions, &velocities, &radii, &mut f1, None);
        parallel.add_forces(&positions, &velocities, &radii, &mut f2, Some(&team));
        serial.settle_held_reaction();
        parallel.settle_held_reaction();
        assert!(
            f1.iter().zip(&f2).all(|(a, b)| a == b),
            "{method:?} {update:?}: forces differ"
        );
        for a in 0..3 {
            assert_eq!(
                serial.momentum_exchange[a], parallel.momentum_exchange[a],
                "{method:?} {update:?}"
            );
        }
    }
}

/// Drag held over a gas step (`gas.drag_update: every_gas_step`): the first sub-step's forces are the every-step
/// scheme's to the bit; later sub-steps keep K, u and the pressure force of that moment with the particle's new
/// velocity and position; the gas then gets, once, exactly what the particles got over the sub-steps.
#[test]
fn held_drag_keeps_the_first_sub_steps_values_and_gives_the_gas_what_the_particles_got() {
    use granflow::engine::gas::held_drag::DragUpdate;
    let sim = settling(1);
    let mut every = sim.gas.as_ref().unwrap().fluid.clone();
    for a in 0..3 {
        for (f, v) in every.velocity_m_per_s[a].iter_mut().enumerate() {
            *v = 0.013 * (f % 5) as f64 - 0.01 * a as f64;
        }
        for (f, g) in every.minus_pressure_gradient_pa_per_m[a].iter_mut().enumerate() {
            *g = 3.0 * (f % 3) as f64;
        }
    }
    let mut held = every.clone();
    held.drag_update = DragUpdate::EveryGasStep;
    let n = 40;
    let mut positions: Vec<Vec3> = (0..n)
        .map(|k| {
            let t = k as f64;
            Vec3::new((t * 0.000_37) % 0.009, (t * 0.000_53) % 0.009, (t * 0.000_71) % 0.03)
        })
        .collect();
    let mut velocities: Vec<Vec3> = (0..n)
        .map(|k| Vec3::new(0.001 * (k % 7) as f64, -0.02, 0.003))
        .collect();
    let radii = vec![RADIUS; n];
    let (mut f_every, mut f_held) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
    every.add_forces(&positions, &velocities, &radii, &mut f_every, None);
    held.add_forces(&positions, &velocities, &radii, &mut f_held, None);
    assert!(
        f_every.iter().zip(&f_held).all(|(a, b)| a == b),
        "first sub-step differs"
    );
    let first = f_held.clone();
    // Three more sub-steps: the particles move across cells and change velocity by dv.
    let mut received = f_held.iter().sum::<Vec3>();
    let dv = Vec3::new(0.01, -0.003, 0.02);
    for _ in 0..3 {
        for (x, v) in positions.iter_mut().zip(velocities.iter_mut()) {
            *x += Vec3::new(0.0011, 0.0007, -0.0013);
            *v += dv;
        }
        let mut f = vec![Vec3::zeros(); n];
        held.add_forces(&positions, &velocities, &radii, &mut f, None);
        received += f.iter().sum::<Vec3>();
        f_held = f;
    }
    // Held K: the force changed by −K dv per sub-step only (position no longer matters).
    for i in 0..n {
        let k = -(f_held[i] - first[i]).x / (3.0 * dv.x);
        let expected = first[i] - dv * (3.0 * k);
        assert!(
            (f_held[i] - expected).norm() <= 1e-12 * first[i].norm().max(1e-12),
            "particle {i}"
        );
        assert!(k > 0.0, "particle {i}: K = {k}");
    }
    // The pressure force is not returned to the gas: what the gas gets is minus the drag alone.
    let pressure: Vec3 = (0..n)
        .map(|i| {
            let volume = 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
            let mut g = Vec3::zeros();
            for a in 0..3 {
                g[a] = granflow::engine::gas::coupling::interpolate_component(
                    &held.grid,
                    &held.minus_pressure_gradient_pa_per_m[a],
                    a,
                    &(positions[i] - Vec3::new(0.0011, 0.0007, -0.0013) * 3.0),
                );
            }
            g * volume
        })
        .sum();
    let drag_received = received - pressure * 4.0;
    assert!(
        held.momentum_exchange[0].transfer_sum.iter().all(|v| *v == 0.0),
        "spread only at the gas step"
    );
    held.settle_held_reaction();
    let volume = held.grid.cell_volume_m3();
    for a in 0..3 {
        let given: f64 = held.momentum_exchange[a].transfer_sum.iter().sum::<f64>() * volume;
        assert!(
            (given + drag_received[a]).abs() <= 1e-10 * drag_received.norm(),
            "axis {a}: gas got {given}, particles {}",
            drag_received[a]
        );
    }
    assert_eq!(held.steps(), 4);
    // Settling twice adds nothing.
    let once = held.momentum_exchange.clone();
    held.settle_held_reaction();
    assert_eq!(once, held.momentum_exchange);
}

/// Cell-averaged drag held over a gas step: the first sub-step is the every-step scheme's to the bit; afterwards
/// each particle keeps its cell of the evaluation and feels K (u_c − v_sm) with that cell's present mean velocity,
/// and the gas gets once exactly what the particles got.
#[test]
fn held_cell_averaged_drag_keeps_the_cells_of_the_evaluation() {
    use granflow::engine::gas::held_drag::DragUpdate;
    let sim = settling(1);
    let mut every = sim.gas.as_ref().unwrap().fluid.clone();
    every.drag_velocities = DragVelocities::CellAveraged;
    for a in 0..3 {
        for (f, v) in every.velocity_m_per_s[a].iter_mut().enumerate() {
            *v = 0.01 * (f % 7) as f64 - 0.02 * a as f64;
        }
        for (f, g) in every.minus_pressure_gradient_pa_per_m[a].iter_mut().enumerate() {
            *g = 2.0 * (f % 4) as f64;
        }
    }
    let mut held = every.clone();
    held.drag_update = DragUpdate::EveryGasStep;
    let mut positions: Vec<Vec3> = (0..9)
        .map(|k| {
            Vec3::new(
                0.0005 + 0.0011 * k as f64,
                0.004 + 0.0003 * (k % 3) as f64,
                0.01 + 0.002 * (k % 4) as f64,
            )
        })
        .collect();
    let mut velocities: Vec<Vec3> = (0..9)
        .map(|k| Vec3::new(0.1 * k as f64, -0.05, 0.02 * (k % 2) as f64))
        .collect();
    let radii: Vec<f64> = (0..9).map(|k| if k == 4 { 1.5 * RADIUS } else { RADIUS }).collect();
    let (mut f_every, mut f_held) = (vec![Vec3::zeros(); 9], vec![Vec3::zeros(); 9]);
    every.add_forces(&positions, &velocities, &radii, &mut f_every, None);
    held.add_forces(&positions, &velocities, &radii, &mut f_held, None);
    assert!(
        f_every.iter().zip(&f_held).all(|(a, b)| a == b),
        "first sub-step differs"
    );
    let mut received: Vec3 = f_held.iter().sum();
    let mut pressure_sum = Vec3::zeros();
    for i in 0..9 {
        let mut g = Vec3::zeros();
        for a in 0..3 {
            g[a] = granflow::engine::gas::coupling::interpolate_component(
                &held.grid,
                &held.minus_pressure_gradient_pa_per_m[a],
                a,
                &positions[i],
            );
        }
        pressure_sum += g * (4.0 / 3.0 * std::f64::consts::PI * radii[i].powi(3));
    }
    // Two more sub-steps, the particles moved by more than a cell: the held forces do not see the move, only the
    // velocity change (one particle's change moves its whole cell's mean).
    for _ in 0..2 {
        for (x, v) in positions.iter_mut().zip(velocities.iter_mut()) {
            *x += Vec3::new(0.002, 0.0, 0.0);
            *v += Vec3::new(0.0, 0.01, 0.0);
        }
        let mut f = vec![Vec3::zeros(); 9];
        held.add_forces(&positions, &velocities, &radii, &mut f, None);
        received += f.iter().sum::<Vec3>();
    }
    held.settle_held_reaction();
    let drag_received = received - pressure_sum * 3.0;
    let volume = held.grid.cell_volume_m3();
    for a in 0..3 {
        let given: f64 = held.momentum_exchange[a].transfer_sum.iter().sum::<f64>() * volume;
        assert!(
            (given + drag_received[a]).abs() <= 1e-10 * drag_received.norm(),
            "axis {a}: gas got {given}, particles {}",
            drag_received[a]
        );
    }
    assert_eq!(held.steps(), 3);
}
