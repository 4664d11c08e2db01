//! Sparse linear systems of the gas solver: the 7-point (3-D) or 5-point (2-D) finite-volume stencil
//! a_P φ_P = Σ a_nb φ_nb + b on a structured grid, solved by conjugate gradients preconditioned by diagonal
//! incomplete Cholesky (symmetric systems: the pressure correction) or Jacobi-preconditioned BiCGStab (momentum,
//! non-symmetric through convection). Each solve first compacts the stencil into rows without absent neighbours.
//!
//! Everything runs in a fixed order on one thread, so a solve gives the same bits every time.

/// The neighbours of a cell in a stencil: index into the unknown vector, or `None` (a boundary: already in `b`).
pub const NEIGHBOURS: usize = 6;

/// A stencil system: for each unknown P, `ap[P] φ_P − Σ_k anb[P][k] φ_{nb[P][k]} = b[P]`.
#[derive(Debug, Clone, Default)]
pub struct StencilSystem {
    pub ap: Vec<f64>,
    pub anb: Vec<[f64; NEIGHBOURS]>,
    pub nb: Vec<[u32; NEIGHBOURS]>,
    pub b: Vec<f64>,
}

/// Marks an absent neighbour in [`StencilSystem::nb`].
pub const NONE: u32 = u32::MAX;

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveReport {
    pub iterations: usize,
    /// ‖b − Aφ‖ / ‖b‖ at the end (0 when b = 0).
    pub relative_residual: f64,
    pub converged: bool,
}

impl StencilSystem {
    pub fn new(n: usize) -> Self {
        StencilSystem {
            ap: vec![0.0; n],
            anb: vec![[0.0; NEIGHBOURS]; n],
            nb: vec![[NONE; NEIGHBOURS]; n],
            b: vec![0.0; n],
        }
    }

    pub fn len(&self) -> usize {
        self.ap.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ap.is_empty()
    }

    /// y = A x.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        for p in 0..self.len() {
            let mut s = self.ap[p] * x[p];
            for k in 0..NEIGHBOURS {
                let q = self.nb[p][k];
                if q != NONE {
                    s -= self.anb[p][k] * x[q as usize];
                }
            }
            y[p] = s;
        }
    }

    #[cfg(test)]
    fn residual(&self, x: &[f64], r: &mut [f64]) {
        self.apply(x, r);
        for (ri, bi) in r.iter_mut().zip(&self.b) {
            *ri = bi - *ri;
        }
    }
}

impl SolveReport {
    /// The report of a system with b = 0 (solved by x = 0).
    const ZERO_RIGHT_HAND_SIDE: SolveReport = SolveReport {
        iterations: 0,
        relative_residual: 0.0,
        converged: true,
    };
}

/// ‖b‖, or `None` after setting x = 0 when b = 0 (the solution; no iteration needed).
fn right_hand_side_norm(sys: &StencilSystem, x: &mut [f64]) -> Option<f64> {
    let b_norm = norm(&sys.b);
    if b_norm == 0.0 {
        x.iter_mut().for_each(|v| *v = 0.0);
        return None;
    }
    Some(b_norm)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// A stencil system compacted for the iterations: the off-diagonal entries of each row as (column, −a_nb), the
/// rows' lower (column < row) entries first, without the absent neighbours (compressed sparse rows).
#[derive(Debug, Clone, Default)]
struct CompactRows {
    diagonal: Vec<f64>,
    /// Row p's entries are `start[p]..start[p + 1]`; the first `lower_end[p] − start[p]` of them are below the
    /// diagonal.
    start: Vec<u32>,
    lower_end: Vec<u32>,
    column: Vec<u32>,
    value: Vec<f64>,
    /// Where each entry's −a_nb comes from: `anb[p][k]` at `p · NEIGHBOURS + k` (flattened).
    source: Vec<u32>,
    /// The stencil's neighbours the structure above was built from: a system with the same ones (a momentum
    /// component's, every outer iteration of every gas step) only refills the values.
    built_from: Vec<[u32; NEIGHBOURS]>,
}

impl CompactRows {
    fn new(sys: &StencilSystem) -> Self {
        let mut rows = CompactRows::default();
        rows.fill(sys);
        rows
    }

    /// Becomes the compacted form of `sys`, reusing its storage.
    fn fill(&mut self, sys: &StencilSystem) {
        let n = sys.len();
        let rows = self;
        rows.diagonal.clear();
        rows.diagonal.extend_from_slice(&sys.ap);
        if rows.built_from == sys.nb {
            let anb = sys.anb.as_flattened();
            for (v, &from) in rows.value.iter_mut().zip(&rows.source) {
                *v = -anb[from as usize];
            }
            return;
        }
        rows.built_from.clone_from(&sys.nb);
        rows.source.clear();
        rows.start.clear();
        rows.lower_end.clear();
        rows.column.clear();
        rows.value.clear();
        rows.start.push(0);
        for p in 0..n {
            for lower in [true, false] {
                for k in 0..NEIGHBOURS {
                    let q = sys.nb[p][k];
                    if q != NONE && ((q as usize) < p) == lower {
                        rows.column.push(q);
                        rows.value.push(-sys.anb[p][k]);
                        rows.source.push((p * NEIGHBOURS + k) as u32);
                    }
                }
                if lower {
                    rows.lower_end.push(rows.column.len() as u32);
                }
            }
            rows.start.push(rows.column.len() as u32);
        }
    }

    /// y = A x.
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        for (p, yp) in y.iter_mut().enumerate() {
            let mut s = self.diagonal[p] * x[p];
            for e in self.start[p] as usize..self.start[p + 1] as usize {
                s += self.value[e] * x[self.column[e] as usize];
            }
            *yp = s;
        }
    }

    /// r = b − A x.
    fn residual(&self, b: &[f64], x: &[f64], r: &mut [f64]) {
        self.apply(x, r);
        for (ri, bi) in r.iter_mut().zip(b) {
            *ri = bi - *ri;
        }
    }
}

/// What a Krylov solve keeps from one system to the next: the compacted rows and the iteration vectors, so that the
/// many small solves of a gas step allocate nothing once the first has sized them. What it keeps between solves is
/// the rows' structure, reused only for a system with the same neighbours (whose compaction would be the same), and
/// vectors that each solve zeroes or overwrites before reading: a solve gives the same bits with a fresh workspace or
/// a used one.
#[derive(Debug, Clone, Default)]
pub struct KrylovWorkspace {
    rows: CompactRows,
    vectors: [Vec<f64>; 9],
}

impl KrylovWorkspace {
    /// The compacted `sys` and nine zeroed vectors of its length.
    fn prepare(&mut self, sys: &StencilSystem) -> (&CompactRows, &mut [Vec<f64>; 9]) {
        self.rows.fill(sys);
        let n = sys.len();
        for v in &mut self.vectors {
            v.clear();
            v.resize(n, 0.0);
        }
        (&self.rows, &mut self.vectors)
    }
}

/// r = b − A x summed as [`CompactRows::residual`] sums it (the diagonal, then the neighbours below the diagonal,
/// then those above, each in stencil order), to the bit, without building the compact rows.
fn residual_in_compact_order(sys: &StencilSystem, x: &[f64], r: &mut [f64]) {
    for (p, rp) in r.iter_mut().enumerate() {
        let mut s = sys.ap[p] * x[p];
        for lower in [true, false] {
            for (&q, &a) in sys.nb[p].iter().zip(&sys.anb[p]) {
                if q != NONE && ((q as usize) < p) == lower {
                    s += (-a) * x[q as usize];
                }
            }
        }
        *rp = sys.b[p] - s;
    }
}

/// Diagonal-based incomplete Cholesky (DIC, as in OpenFOAM's PCG): M = (D + L) D⁻¹ (D + Lᵀ) with L the strictly
/// lower part of A (in unknown order) and D chosen so that diag(M) = diag(A): d_p = a_p − Σ_{k<p} a_pk² / d_k.
/// For the pressure-correction Poisson systems it needs about a third of the iterations of Jacobi. Where the
/// factorisation breaks down (d_p not clearly positive, e.g. the last row of a singular Neumann system) d_p falls
/// back to a_p.
struct DiagonalIncompleteCholesky {
    inverse_d: Vec<f64>,
}

impl DiagonalIncompleteCholesky {
    fn new(rows: &CompactRows) -> Self {
        let n = rows.diagonal.len();
        let mut inverse_d = vec![0.0; n];
        for p in 0..n {
            let ap = rows.diagonal[p];
            let mut dp = ap;
            for e in rows.start[p] as usize..rows.lower_end[p] as usize {
                dp -= rows.value[e] * rows.value[e] * inverse_d[rows.column[e] as usize];
            }
            let d = if dp > 1e-3 * ap && dp.is_finite() {
                dp
            } else if ap != 0.0 {
                ap
            } else {
                1.0
            };
            inverse_d[p] = 1.0 / d;
        }
        DiagonalIncompleteCholesky { inverse_d }
    }

    /// z = M⁻¹ r: forward (D + L) w = r, then backward (D + Lᵀ) z = D w.
    fn apply(&self, rows: &CompactRows, r: &[f64], z: &mut [f64]) {
        let n = rows.diagonal.len();
        for p in 0..n {
            let mut s = r[p];
            for e in rows.start[p] as usize..rows.lower_end[p] as usize {
                s -= rows.value[e] * z[rows.column[e] as usize];
            }
            z[p] = s * self.inverse_d[p];
        }
        for p in (0..n).rev() {
            let mut s = 0.0;
            for e in rows.lower_end[p] as usize..rows.start[p + 1] as usize {
                s -= rows.value[e] * z[rows.column[e] as usize];
            }
            z[p] += s * self.inverse_d[p];
        }
    }
}

/// Conjugate gradients preconditioned by diagonal-based incomplete Cholesky for a symmetric system; `x` holds the start and the result. A singular
/// but consistent system (pure Neumann pressure correction) converges to a solution; `remove_mean` then subtracts
/// the mean of `x` (the undetermined constant).
pub fn conjugate_gradient(
    sys: &StencilSystem,
    x: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
    remove_mean: bool,
) -> SolveReport {
    let n = sys.len();
    let Some(b_norm) = right_hand_side_norm(sys, x) else {
        return SolveReport::ZERO_RIGHT_HAND_SIDE;
    };
    let rows = CompactRows::new(sys);
    let precond = DiagonalIncompleteCholesky::new(&rows);
    let mut r = vec![0.0; n];
    rows.residual(&sys.b, x, &mut r);
    let mut z = vec![0.0; n];
    precond.apply(&rows, &r, &mut z);
    let mut p = z.clone();
    let mut q = vec![0.0; n];
    let mut rz = dot(&r, &z);
    let mut iterations = 0;
    let mut rel = norm(&r) / b_norm;
    while rel > tolerance && iterations < max_iterations {
        rows.apply(&p, &mut q);
        let pq = dot(&p, &q);
        if pq == 0.0 {
            break;
        }
        let alpha = rz / pq;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
        }
        precond.apply(&rows, &r, &mut z);
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
        iterations += 1;
        rel = norm(&r) / b_norm;
    }
    if remove_mean && n > 0 {
        let mean = x.iter().sum::<f64>() / n as f64;
        x.iter_mut().for_each(|v| *v -= mean);
    }
    SolveReport {
        iterations,
        relative_residual: rel,
        converged: rel <= tolerance,
    }
}

/// How the pressure-correction systems are solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum PressureSolver {
    /// `direct` when its factorisation costs less than [`DIRECT_WORK_LIMIT`] multiply-adds (n·b², b the
    /// bandwidth: small 2-D grids), `conjugate_gradient` otherwise.
    #[default]
    Auto,
    /// Banded LDLᵀ factorisation and exact solve (cost independent of conditioning: packed layers with a large
    /// drag make the pressure systems stiff for iterative solvers).
    Direct,
    /// Conjugate gradients preconditioned by diagonal incomplete Cholesky, to `linear_tolerance`.
    ConjugateGradient,
}

/// Largest n·b² (n unknowns, b bandwidth) for which `auto` factorises: about a millisecond.
pub const DIRECT_WORK_LIMIT: usize = 3_000_000;

impl PressureSolver {
    /// Whether a system of `n` unknowns and bandwidth `b` is solved directly.
    pub fn direct_for(self, n: usize, bandwidth: usize) -> bool {
        match self {
            PressureSolver::Auto => n.saturating_mul(bandwidth).saturating_mul(bandwidth) <= DIRECT_WORK_LIMIT,
            PressureSolver::Direct => true,
            PressureSolver::ConjugateGradient => false,
        }
    }
}

/// The largest |q − p| over the system's entries.
pub fn bandwidth(sys: &StencilSystem) -> usize {
    let mut b = 0;
    for (p, nb) in sys.nb.iter().enumerate() {
        for &q in nb {
            if q != NONE {
                b = b.max(p.abs_diff(q as usize));
            }
        }
    }
    b
}

/// Solves a symmetric system exactly by banded LDLᵀ factorisation (no pivoting: the pressure-correction systems
/// are symmetric, weakly diagonally dominant M-matrices). A pivot that vanishes (the last unknown of a singular
/// pure-Neumann system, one per connected region) pins that unknown to 0, which solves a consistent singular
/// system; `remove_mean` then subtracts the mean of `x`. Reports 1 iteration and the true relative residual.
pub fn direct_symmetric(sys: &StencilSystem, x: &mut [f64], remove_mean: bool) -> SolveReport {
    let n = sys.len();
    let Some(b_norm) = right_hand_side_norm(sys, x) else {
        return SolveReport::ZERO_RIGHT_HAND_SIDE;
    };
    let (mut l, bw) = lower_band(sys);
    let width = bw + 1;
    eliminate_band(&mut l, &sys.ap, n, bw);
    // L y = b, z = D⁻¹ y, Lᵀ x = z.
    x.copy_from_slice(&sys.b);
    for p in 0..n {
        let first = p.saturating_sub(bw);
        let row_p = &l[p * width..(p + 1) * width];
        let (solved, rest) = x.split_at_mut(p);
        let mut s = rest[0];
        for (l_pj, x_j) in row_p[bw - (p - first)..bw].iter().zip(&solved[first..]) {
            s -= l_pj * x_j;
        }
        rest[0] = s;
    }
    for p in 0..n {
        x[p] *= l[p * width + bw];
    }
    for p in (0..n).rev() {
        let first = p.saturating_sub(bw);
        let row_p = &l[p * width..(p + 1) * width];
        let (earlier, rest) = x.split_at_mut(p);
        let xp = rest[0];
        for (x_j, l_pj) in earlier[first..].iter_mut().zip(&row_p[bw - (p - first)..bw]) {
            *x_j -= l_pj * xp;
        }
    }
    if remove_mean && n > 0 {
        let mean = x.iter().sum::<f64>() / n as f64;
        x.iter_mut().for_each(|v| *v -= mean);
    }
    let mut r = vec![0.0; n];
    residual_in_compact_order(sys, x, &mut r);
    let relative_residual = norm(&r) / b_norm;
    SolveReport {
        iterations: 1,
        relative_residual,
        converged: relative_residual.is_finite(),
    }
}

/// The lower band of `sys` and its bandwidth bw: row p's entry for column q, p − bw ≤ q ≤ p, at
/// l[p · (bw + 1) + (q + bw − p)] (the diagonal last). [`eliminate_band`] overwrites it with L (unit diagonal, not
/// stored) and D⁻¹ in the diagonal slot.
fn lower_band(sys: &StencilSystem) -> (Vec<f64>, usize) {
    let (n, bw) = (sys.len(), bandwidth(sys));
    let width = bw + 1;
    let mut l = vec![0.0; n * width];
    for p in 0..n {
        l[p * width + bw] = sys.ap[p];
        for k in 0..NEIGHBOURS {
            let q = sys.nb[p][k];
            if q != NONE && (q as usize) < p {
                l[p * width + (q as usize + bw - p)] -= sys.anb[p][k];
            }
        }
    }
    (l, bw)
}

/// The right-looking LDLᵀ elimination of [`direct_symmetric`] on its band `l` (row p's entry for column j,
/// p − bw ≤ j ≤ p, at l[p · (bw + 1) + (j + bw − p)]; `ap` the original diagonal, for the pivot test): L below the
/// diagonal, D⁻¹ on it.
///
/// Once pivot k is final, its column below the diagonal is scaled into L and every later entry it touches is
/// updated, A_pj −= (L_pk d_k) L_jk for k < j ≤ p ≤ k + bw. Each entry receives the same products in the same order
/// (ascending k) as the textbook left-looking loops (so the same bits), but the updates of one pivot are independent
/// of each other, where the left-looking dot products were one chain of dependent subtractions each (one
/// multiply-add per four cycles). Compiled a second time for x86-64-v3 (four-wide vectors) and chosen at run time,
/// as the pair pass is; multiplications and subtractions stay separate, so both give the same bits.
fn eliminate_band(l: &mut [f64], ap: &[f64], n: usize, bw: usize) {
    #[cfg(target_arch = "x86_64")]
    if crate::machine::cpu_fast_path() {
        // SAFETY: `cpu_fast_path` is true only where the CPU has every feature the function is compiled for.
        return unsafe { eliminate_band_x86_64_v3(l, ap, n, bw) };
    }
    eliminate_band_body(l, ap, n, bw);
}

/// [`eliminate_band_body`] compiled for x86-64-v3's instructions.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,movbe")]
fn eliminate_band_x86_64_v3(l: &mut [f64], ap: &[f64], n: usize, bw: usize) {
    eliminate_band_body(l, ap, n, bw);
}

#[inline(always)]
fn eliminate_band_body(l: &mut [f64], ap: &[f64], n: usize, bw: usize) {
    let width = bw + 1;
    let mut unscaled = vec![0.0; bw];
    let mut scaled = vec![0.0; bw];
    for k in 0..n {
        let d = l[k * width + bw];
        let d_inverse = if d > 1e-12 * ap[k].abs() && d.is_finite() {
            1.0 / d
        } else {
            0.0
        };
        l[k * width + bw] = d_inverse;
        let below = bw.min(n - 1 - k);
        // Column k, rows k + 1 ..= k + below: w_ik = L_ik d_k (final now) and L_ik.
        for m in 0..below {
            let i = k + 1 + m;
            let entry = &mut l[i * width + (k + bw - i)];
            unscaled[m] = *entry;
            scaled[m] = *entry * d_inverse;
            *entry = scaled[m];
        }
        for m in 0..below {
            let p = k + 1 + m;
            let w_pk = unscaled[m];
            // Columns j = k + 1 ..= p of row p.
            let row = &mut l[p * width + (k + 1 + bw - p)..(p + 1) * width];
            for (a_pj, l_jk) in row.iter_mut().zip(&scaled[..=m]) {
                *a_pj -= w_pk * l_jk;
            }
        }
    }
}

/// Jacobi-preconditioned BiCGStab (van der Vorst 1992) for a non-symmetric system; `x` holds the start and the
/// result.
pub fn bicgstab(sys: &StencilSystem, x: &mut [f64], tolerance: f64, max_iterations: usize) -> SolveReport {
    bicgstab_in(&mut KrylovWorkspace::default(), sys, x, tolerance, max_iterations)
}

/// [`bicgstab`] in the storage of `workspace`.
pub fn bicgstab_in(
    workspace: &mut KrylovWorkspace,
    sys: &StencilSystem,
    x: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
) -> SolveReport {
    let n = sys.len();
    let Some(b_norm) = right_hand_side_norm(sys, x) else {
        return SolveReport::ZERO_RIGHT_HAND_SIDE;
    };
    let (rows, [inv_diag, r, r_hat, v, p, y, s, z, t]) = workspace.prepare(sys);
    for (d, a) in inv_diag.iter_mut().zip(&sys.ap) {
        *d = if *a != 0.0 { 1.0 / a } else { 1.0 };
    }
    rows.residual(&sys.b, x, r);
    r_hat.copy_from_slice(r);
    let (mut rho, mut alpha, mut omega) = (1.0, 1.0, 1.0);
    let mut iterations = 0;
    let mut rel = norm(r) / b_norm;
    while rel > tolerance && iterations < max_iterations {
        let rho_new = dot(r_hat, r);
        if rho_new == 0.0 || omega == 0.0 {
            break;
        }
        let beta = (rho_new / rho) * (alpha / omega);
        rho = rho_new;
        for i in 0..n {
            p[i] = r[i] + beta * (p[i] - omega * v[i]);
            y[i] = p[i] * inv_diag[i];
        }
        rows.apply(y, v);
        let rv = dot(r_hat, v);
        if rv == 0.0 {
            break;
        }
        alpha = rho / rv;
        for i in 0..n {
            s[i] = r[i] - alpha * v[i];
        }
        if norm(s) / b_norm <= tolerance {
            for i in 0..n {
                x[i] += alpha * y[i];
            }
            r.copy_from_slice(s);
            iterations += 1;
            break;
        }
        for i in 0..n {
            z[i] = s[i] * inv_diag[i];
        }
        rows.apply(z, t);
        let tt = dot(t, t);
        omega = if tt > 0.0 { dot(t, s) / tt } else { 0.0 };
        for i in 0..n {
            x[i] += alpha * y[i] + omega * z[i];
            r[i] = s[i] - omega * t[i];
        }
        iterations += 1;
        rel = norm(r) / b_norm;
    }
    // The recursively updated residual drifts from the true one: report the true one, and call it converged
    // within a factor 10 of the tolerance (the size of that drift).
    rows.residual(&sys.b, x, r);
    rel = norm(r) / b_norm;
    SolveReport {
        iterations,
        relative_residual: rel,
        converged: rel <= 10.0 * tolerance,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1-D Poisson −φ'' = 1 on n interior points with φ = 0 at both ends: φ_i = x(1−x)/2 exactly at the nodes.
    fn poisson_1d(n: usize, convection: f64) -> StencilSystem {
        let h = 1.0 / (n + 1) as f64;
        let mut sys = StencilSystem::new(n);
        for i in 0..n {
            sys.ap[i] = 2.0 / (h * h);
            sys.b[i] = 1.0;
            if i > 0 {
                sys.nb[i][0] = (i - 1) as u32;
                sys.anb[i][0] = 1.0 / (h * h) + convection / h;
                sys.ap[i] += convection / h;
            }
            if i + 1 < n {
                sys.nb[i][1] = (i + 1) as u32;
                sys.anb[i][1] = 1.0 / (h * h);
            }
        }
        sys
    }

    #[test]
    fn conjugate_gradient_solves_poisson_to_the_exact_nodal_values() {
        let n = 99;
        let sys = poisson_1d(n, 0.0);
        let mut x = vec![0.0; n];
        let report = conjugate_gradient(&sys, &mut x, 1e-12, 1000, false);
        assert!(report.converged, "{report:?}");
        let h = 1.0 / (n + 1) as f64;
        for (i, xi) in x.iter().enumerate() {
            let s = (i + 1) as f64 * h;
            assert!((xi - s * (1.0 - s) / 2.0).abs() < 1e-10, "{i}: {xi}");
        }
    }

    /// A 2-D pure-Neumann Poisson system (singular, consistent right-hand side) on an nx × ny grid with
    /// coefficients varying over orders of magnitude, as in a bed with a packed layer.
    fn neumann_2d(nx: usize, ny: usize) -> StencilSystem {
        let n = nx * ny;
        let mut sys = StencilSystem::new(n);
        let coefficient = |p: usize, q: usize| 1.0 + 1e3 * ((p * 7 + q * 13).is_multiple_of(5) as u8 as f64);
        for j in 0..ny {
            for i in 0..nx {
                let p = i + nx * j;
                let neighbours = [
                    (i > 0).then(|| p - 1),
                    (i + 1 < nx).then(|| p + 1),
                    (j > 0).then(|| p - nx),
                    (j + 1 < ny).then(|| p + nx),
                ];
                for (k, q) in neighbours.into_iter().enumerate() {
                    if let Some(q) = q {
                        let c = coefficient(p.min(q), p.max(q));
                        sys.nb[p][k] = q as u32;
                        sys.anb[p][k] = c;
                        sys.ap[p] += c;
                    }
                }
                sys.b[p] = ((p * 31) % 17) as f64 - 8.0;
            }
        }
        let mean = sys.b.iter().sum::<f64>() / n as f64;
        sys.b.iter_mut().for_each(|v| *v -= mean);
        sys
    }

    #[test]
    fn direct_solve_matches_conjugate_gradients_on_a_singular_stiff_system() {
        let sys = neumann_2d(15, 45);
        assert_eq!(bandwidth(&sys), 15);
        let mut direct = vec![0.0; sys.len()];
        let report = direct_symmetric(&sys, &mut direct, true);
        assert!(report.relative_residual < 1e-10, "{report:?}");
        let mut cg = vec![0.0; sys.len()];
        let iterative = conjugate_gradient(&sys, &mut cg, 1e-12, 5000, true);
        assert!(iterative.converged, "{iterative:?}");
        let scale = cg.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, b) in direct.iter().zip(&cg) {
            assert!((a - b).abs() < 1e-8 * scale, "{a} vs {b}");
        }
    }

    /// The right-looking elimination gives the textbook left-looking factors to the bit (each entry gets the same
    /// products in the same order), on the baseline and on the x86-64-v3 compilation alike.
    #[test]
    fn right_looking_elimination_gives_the_left_looking_factors_to_the_bit() {
        let sys = neumann_2d(15, 45);
        let (mut left, bw) = lower_band(&sys);
        let (n, width) = (sys.len(), bw + 1);
        // Left-looking, as the factorisation was first written.
        let mut w = vec![0.0; width];
        for p in 0..n {
            let first = p.saturating_sub(bw);
            for j in first..p {
                let mut a = left[p * width + (j + bw - p)];
                for k in first.max(j.saturating_sub(bw))..j {
                    a -= w[k - first] * left[j * width + (k + bw - j)];
                }
                w[j - first] = a;
                left[p * width + (j + bw - p)] = a * left[j * width + bw];
            }
            let mut d = left[p * width + bw];
            for j in first..p {
                d -= w[j - first] * left[p * width + (j + bw - p)];
            }
            left[p * width + bw] = if d > 1e-12 * sys.ap[p].abs() && d.is_finite() {
                1.0 / d
            } else {
                0.0
            };
        }
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let (mut right, _) = lower_band(&sys);
        eliminate_band_body(&mut right, &sys.ap, n, bw);
        assert_eq!(bits(&right), bits(&left));
        #[cfg(target_arch = "x86_64")]
        if crate::machine::cpu_fast_path() {
            let (mut fast, _) = lower_band(&sys);
            // SAFETY: `cpu_fast_path` is true only where the CPU has every feature the function is compiled for.
            unsafe { eliminate_band_x86_64_v3(&mut fast, &sys.ap, n, bw) };
            assert_eq!(bits(&fast), bits(&left));
        }
    }

    #[test]
    fn direct_solve_is_exact_for_poisson_1d() {
        let n = 99;
        let sys = poisson_1d(n, 0.0);
        let mut x = vec![0.0; n];
        let report = direct_symmetric(&sys, &mut x, false);
        assert!(report.relative_residual < 1e-11, "{report:?}");
        let h = 1.0 / (n + 1) as f64;
        for (i, xi) in x.iter().enumerate() {
            let s = (i + 1) as f64 * h;
            assert!((xi - s * (1.0 - s) / 2.0).abs() < 1e-12, "{i}: {xi}");
        }
    }

    #[test]
    fn auto_factorises_small_grids_only() {
        assert!(PressureSolver::Auto.direct_for(15 * 45, 15));
        assert!(!PressureSolver::Auto.direct_for(40 * 40 * 80, 1600));
        assert!(PressureSolver::Direct.direct_for(40 * 40 * 80, 1600));
        assert!(!PressureSolver::ConjugateGradient.direct_for(10, 1));
    }

    #[test]
    fn bicgstab_solves_a_non_symmetric_system() {
        let n = 80;
        let sys = poisson_1d(n, 30.0);
        let mut x = vec![0.0; n];
        let report = bicgstab(&sys, &mut x, 1e-11, 2000);
        assert!(report.converged, "{report:?}");
        let mut r = vec![0.0; n];
        sys.residual(&x, &mut r);
        assert!(norm(&r) / norm(&sys.b) < 1e-10, "{report:?}");
    }
}
