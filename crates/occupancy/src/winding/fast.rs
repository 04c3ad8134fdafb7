//! Fast generalized winding numbers: Barill, Dickson, Schmidt, Levin, Jacobson, "Fast
//! Winding Numbers for Soups and Clouds", ACM TOG 37(4), 2018.
//!
//! Each BVH node stores the moments of its triangles about its area-weighted centroid
//! `p̃`; a query `q` farther than `β·R` from `p̃` (`R`: radius of the node's bounding ball
//! around `p̃`) uses the order-2 Taylor expansion of the dipole field
//! `f(x) = (x − q) / |x − q|³` around `p̃`, integrated against the normals:
//!
//! `∫ f·n dA ≈ r·N/ρ³ + tr(C)/ρ³ − 3 rᵀCr/ρ⁵
//!            + ½ [−3 (2 r·a + r·b)/ρ⁵ + 15 Σ r_j r_k r_i T_jki / ρ⁷]`
//!
//! with `r = p̃ − q`, `ρ = |r|`, `d = x − p̃`, `N = ∫ n dA`, `C_ji = ∫ d_j n_i dA`,
//! `T_jki = ∫ d_j d_k n_i dA`, `a_j = Σ_k T_jkk`, `b_i = Σ_j T_jji`. The moments are exact
//! triangle integrals (normals are constant per triangle; `∫ d dA = A s/3` and
//! `∫ d dᵀ dA = A/12 (Σ_v v vᵀ + s sᵀ)` with `s` the sum of the corners relative to `p̃`),
//! not point approximations. Nearby leaves are summed exactly with
//! [`super::solid_angle::solid_angle`].

use rayon::prelude::*;

use super::solid_angle::{solid_angle, solid_angle_lanes};
use crate::bvh::TriangleBvh;
use vf_common::vec3::{add, cross, dot, scale, sub, V3};

/// Index of the symmetric pair `(j, k)` in the 6-entry packing xx, xy, xz, yy, yz, zz.
const PAIR: [[usize; 3]; 3] = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];

/// Expansion data of one BVH node (all f64, mesh frame, moments about its centre).
#[derive(Clone, Copy, Debug, Default)]
pub struct FastNode {
    /// Area-weighted centroid p̃ of the node's triangles, mesh frame.
    pub center: V3,
    /// Squared expansion radius `(β·R)²`, mesh units²: the expansion is used beyond it.
    pub far_squared: f64,
    /// The moments used by [`FastNode::eval`].
    pub moments: Moments,
}

/// Moments of a node's triangles about its centre p̃ (`d = x − p̃`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Moments {
    /// `N = Σ ∫ n dA` (area-weighted normal sum), mesh units².
    pub n: V3,
    /// `C[3j+i] = ∫ d_j n_i dA`, mesh units³.
    pub c: [f64; 9],
    /// `T[3·PAIR[j][k] + i] = ∫ d_j d_k n_i dA`, mesh units⁴.
    pub t: [f64; 18],
}

/// The expansion reduced to what the evaluation needs (24 f64 = 3 cache lines): only the
/// symmetric parts of `C` and `T` contribute, so
/// `eval = (r·N + tr C)/ρ³ + (−3 rᵀCr − 1.5 r·(2a + b))/ρ⁵ + 7.5 Σ T_jki r_j r_k r_i/ρ⁷`
/// with the quadratic and cubic forms stored as 6 and 10 monomial coefficients.
#[derive(Clone, Copy, Debug)]
pub struct PackedMoments {
    /// `[N (3), tr C, Q: xx yy zz xy xz yz (6), h = −1.5(2a+b) (3),
    ///   7.5·P: xxx yyy zzz xxy xxz xyy yyz xzz yzz xyz (10), 0]`.
    pub k: [f64; 24],
}

impl Default for PackedMoments {
    fn default() -> Self {
        PackedMoments { k: [0.0; 24] }
    }
}

impl From<&Moments> for PackedMoments {
    fn from(m: &Moments) -> Self {
        let c = &m.c; // c[3j+i] = C_ji
        let t = |j: usize, k: usize, i: usize| m.t[3 * PAIR[j][k] + i];
        let a: [f64; 3] = std::array::from_fn(|j| t(j, 0, 0) + t(j, 1, 1) + t(j, 2, 2));
        let b: [f64; 3] = std::array::from_fn(|i| t(0, 0, i) + t(1, 1, i) + t(2, 2, i));
        // Coefficient of r_a² r_b in the cubic form: T_aa,b + 2 T_ab,a.
        let aab = |a: usize, b: usize| t(a, a, b) + 2.0 * t(a, b, a);
        let mut k = [0.0; 24];
        k[0..3].copy_from_slice(&m.n);
        k[3] = c[0] + c[4] + c[8];
        k[4] = c[0];
        k[5] = c[4];
        k[6] = c[8];
        k[7] = c[1] + c[3];
        k[8] = c[2] + c[6];
        k[9] = c[5] + c[7];
        for j in 0..3 {
            k[10 + j] = -1.5 * (2.0 * a[j] + b[j]);
        }
        let cubic = [
            t(0, 0, 0),
            t(1, 1, 1),
            t(2, 2, 2),
            aab(0, 1),
            aab(0, 2),
            aab(1, 0),
            aab(1, 2),
            aab(2, 0),
            aab(2, 1),
            2.0 * (t(0, 1, 2) + t(0, 2, 1) + t(1, 2, 0)),
        ];
        for (dst, v) in k[13..23].iter_mut().zip(cubic) {
            *dst = 7.5 * v;
        }
        PackedMoments { k }
    }
}

impl PackedMoments {
    /// Same value as [`Moments::eval`], with about half the arithmetic.
    #[inline(always)]
    pub fn eval(&self, r: V3, rho2: f64) -> f64 {
        let k = &self.k;
        let [x, y, z] = r;
        let (xx, yy, zz) = (x * x, y * y, z * z);
        let s3 = x * k[0] + y * k[1] + z * k[2] + k[3];
        let quad = xx * k[4] + yy * k[5] + zz * k[6] + x * y * k[7] + x * z * k[8] + y * z * k[9];
        let s5 = -3.0 * quad + x * k[10] + y * k[11] + z * k[12];
        let s7 = x * (xx * k[13] + yy * k[18] + zz * k[20] + y * z * k[22])
            + y * (yy * k[14] + xx * k[16] + zz * k[21])
            + z * (zz * k[15] + xx * k[17] + yy * k[19]);
        let inv_rho2 = 1.0 / rho2;
        let inv_rho3 = inv_rho2 * inv_rho2.sqrt();
        (s3 + (s5 + s7 * inv_rho2) * inv_rho2) * inv_rho3
    }
}

/// What the fast traversal reads for every visited node (40 bytes; siblings are adjacent).
#[derive(Clone, Copy, Debug, Default)]
pub struct HotNode {
    /// `[p̃x, p̃y, p̃z, (β·R)²]`, mesh frame / mesh units².
    pub center_far: [f64; 4],
    /// Inner node: `[left child, u32::MAX]`; leaf: slot range `[lo, hi)`.
    pub link: [u32; 2],
}

/// The expansions of all nodes in two parallel arrays (#nodes each), split so the
/// traversal's acceptance test touches 40 bytes per node and the 240 bytes of moments
/// only when a node is expanded.
#[derive(Clone, Debug, Default)]
pub struct FastNodes {
    /// Per node: centre, squared acceptance radius and topology.
    pub hot: Vec<HotNode>,
    /// Per node: packed moments about p̃.
    pub moments: Vec<PackedMoments>,
}

/// Computes the expansion of every node (parallel over nodes; each node is computed on
/// its own from its triangles, so results do not depend on the thread count).
///
/// - `bvh`: the triangle BVH.
/// - `beta`: accuracy parameter β (> 1).
/// - returns: expansions indexed like `bvh`'s nodes.
///
/// # Complexity
/// O(F · depth).
pub fn build_fast_nodes(bvh: &TriangleBvh, beta: f64) -> FastNodes {
    let all: Vec<FastNode> = (0..bvh.num_nodes())
        .into_par_iter()
        .map(|n| {
            let [lo, hi] = bvh.range[n];
            if lo >= hi {
                return FastNode::default();
            }
            node_expansion(&bvh.corners[lo as usize..hi as usize], beta)
        })
        .collect();
    FastNodes {
        hot: all
            .iter()
            .enumerate()
            .map(|(n, f)| HotNode {
                center_far: [f.center[0], f.center[1], f.center[2], f.far_squared],
                link: if bvh.is_leaf(n as u32) { bvh.range[n] } else { [bvh.left_child(n as u32), u32::MAX] },
            })
            .collect(),
        moments: all.iter().map(|f| PackedMoments::from(&f.moments)).collect(),
    }
}

fn node_expansion(tris: &[[V3; 3]], beta: f64) -> FastNode {
    // Area-weighted centroid (falls back to the plain corner mean for zero total area).
    let mut area_sum = 0.0;
    let mut weighted = [0.0; 3];
    let mut mean = [0.0; 3];
    for t in tris {
        let an = scale(cross(sub(t[1], t[0]), sub(t[2], t[0])), 0.5);
        let area = dot(an, an).sqrt();
        let cen = scale(add(add(t[0], t[1]), t[2]), 1.0 / 3.0);
        area_sum += area;
        weighted = add(weighted, scale(cen, area));
        mean = add(mean, cen);
    }
    let center = if area_sum > 0.0 { scale(weighted, 1.0 / area_sum) } else { scale(mean, 1.0 / tris.len() as f64) };
    let mut node = FastNode { center, ..FastNode::default() };
    let mut radius_squared: f64 = 0.0;
    for t in tris {
        let v = [sub(t[0], center), sub(t[1], center), sub(t[2], center)];
        for w in v {
            radius_squared = radius_squared.max(dot(w, w));
        }
        // Area vector A·n (the integral of n over the triangle).
        let an = scale(cross(sub(t[1], t[0]), sub(t[2], t[0])), 0.5);
        let s = add(add(v[0], v[1]), v[2]);
        node.moments.n = add(node.moments.n, an);
        for j in 0..3 {
            // ∫ d_j dA = A s_j / 3, times the constant normal.
            for (i, a) in an.iter().enumerate() {
                node.moments.c[3 * j + i] += s[j] / 3.0 * a;
            }
            for k in j..3 {
                // ∫ d_j d_k dA = A/12 (Σ v_j v_k + s_j s_k).
                let m = (v[0][j] * v[0][k] + v[1][j] * v[1][k] + v[2][j] * v[2][k] + s[j] * s[k]) / 12.0;
                let p = PAIR[j][k];
                for (i, a) in an.iter().enumerate() {
                    node.moments.t[3 * p + i] += m * a;
                }
            }
        }
    }
    let far = beta * radius_squared.sqrt();
    node.far_squared = far * far;
    node
}

impl FastNode {
    /// See [`Moments::eval`].
    #[inline(always)]
    pub fn eval(&self, r: V3, rho2: f64) -> f64 {
        self.moments.eval(r, rho2)
    }
}

impl Moments {
    /// The order-2 expansion of `∫ (x−q)·n / |x−q|³ dA` over the node (that is, 4π times
    /// its winding-number contribution), for `r = center − q` and `rho2 = |r|²`.
    #[inline(always)]
    pub fn eval(&self, r: V3, rho2: f64) -> f64 {
        let inv_rho2 = 1.0 / rho2;
        let inv_rho = inv_rho2.sqrt();
        let inv_rho3 = inv_rho * inv_rho2;
        let inv_rho5 = inv_rho3 * inv_rho2;
        let inv_rho7 = inv_rho5 * inv_rho2;
        let c = &self.c;
        let t = &self.t;
        // Order 0.
        let order0 = dot(r, self.n) * inv_rho3;
        // Order 1: tr(C)/ρ³ − 3 rᵀ C r / ρ⁵ with C[3j+i] = C_ji.
        let trace = c[0] + c[4] + c[8];
        let mut rcr = 0.0;
        for j in 0..3 {
            rcr += r[j] * (c[3 * j] * r[0] + c[3 * j + 1] * r[1] + c[3 * j + 2] * r[2]);
        }
        let order1 = trace * inv_rho3 - 3.0 * rcr * inv_rho5;
        // Order 2.
        // a_j = Σ_k T_jkk, b_i = Σ_j T_jji.
        let a = [
            t[3 * PAIR[0][0]] + t[3 * PAIR[0][1] + 1] + t[3 * PAIR[0][2] + 2],
            t[3 * PAIR[1][0]] + t[3 * PAIR[1][1] + 1] + t[3 * PAIR[1][2] + 2],
            t[3 * PAIR[2][0]] + t[3 * PAIR[2][1] + 1] + t[3 * PAIR[2][2] + 2],
        ];
        let b = [t[0] + t[9] + t[15], t[1] + t[10] + t[16], t[2] + t[11] + t[17]];
        // Σ_jk r_j r_k (Σ_i T_jki r_i), symmetric pairs counted twice off the diagonal.
        let mut tr = [0.0; 6];
        for (p, tp) in tr.iter_mut().enumerate() {
            *tp = t[3 * p] * r[0] + t[3 * p + 1] * r[1] + t[3 * p + 2] * r[2];
        }
        let rrr = r[0] * r[0] * tr[0]
            + r[1] * r[1] * tr[3]
            + r[2] * r[2] * tr[5]
            + 2.0 * (r[0] * r[1] * tr[1] + r[0] * r[2] * tr[2] + r[1] * r[2] * tr[4]);
        let order2 = 0.5 * (-3.0 * (2.0 * dot(r, a) + dot(r, b)) * inv_rho5 + 15.0 * rrr * inv_rho7);
        order0 + order1 + order2
    }
}

/// Fast winding number at `q` times 4π (no exact fallback; see
/// [`MeshOracle::winding_number`](crate::MeshOracle::winding_number) for the guarded
/// version).
///
/// Children are tested from their parent, so accepted nodes are never pushed.
///
/// - `q`: query point, mesh frame.
/// - `stack`: reusable traversal stack (cleared on entry).
pub(crate) fn fast_solid_angle_sum(bvh: &TriangleBvh, nodes: &FastNodes, q: V3, stack: &mut Vec<u32>) -> f64 {
    let hot = &nodes.hot[..];
    let moments = &nodes.moments[..];
    let corners = &bvh.corners[..];
    let mut sum = 0.0;
    stack.clear();
    stack.push(0);
    while let Some(n) = stack.pop() {
        let h = &hot[n as usize];
        let cf = &h.center_far;
        let r = [cf[0] - q[0], cf[1] - q[1], cf[2] - q[2]];
        let rho2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        if rho2 > cf[3] {
            sum += moments[n as usize].eval(r, rho2);
        } else if h.link[1] != u32::MAX {
            for t in &corners[h.link[0] as usize..h.link[1] as usize] {
                sum += solid_angle(q, t[0], t[1], t[2]);
            }
        } else {
            let l = h.link[0];
            stack.push(l + 1);
            stack.push(l);
        }
    }
    sum
}

/// Queries per packet of [`fast_solid_angle_sums`] with AVX2 or plain SSE2. Measured
/// single-threaded on the bunny and a 20,480-face icosphere (200k issue queries): 8 lanes
/// 3.5 µs/query, 16 lanes 2.9, 32 lanes 3.5–4.2 (the packets' union of visited nodes grows
/// faster than the 4-wide vectors gain).
pub(crate) const LANES: usize = 16;

/// Queries per packet with AVX-512 (8 f64 per vector). One thread, 400k issue queries,
/// 8-triangle leaves: 16 lanes 1.41 µs/query on the icosphere, 32 lanes 1.30, 64 lanes 1.69
/// (AVX2 at 16 lanes: 1.62).
pub(crate) const LANES_AVX512: usize = 32;

/// One bit per lane of a packet (at most 32 lanes).
pub(crate) type LaneMask = u32;

/// [`fast_solid_angle_sum`] for many queries, traversed in packets of [`LANES`] (or
/// [`LANES_AVX512`]) consecutive queries (callers pass them in a spatially coherent
/// order, e.g. Morton).
///
/// A packet walks the tree once with a lane mask: at each node the acceptance test runs
/// for all lanes at once, the expansion is evaluated for every lane that accepts it (all
/// lanes in one vectorisable loop when several do), and the children are visited only by
/// the lanes that did not. Nearby queries accept and open mostly the same nodes, so each
/// node's 40-byte record and 192-byte moments are loaded once per packet instead of once
/// per query, and the acceptance branch becomes a mask test. Every lane adds exactly the
/// terms [`fast_solid_angle_sum`] adds for its query, in the same order and with the same
/// arithmetic, so the results are bit-identical to the one-query traversal whatever the
/// packet width or instruction set (tested).
///
/// - `qs`: #Q query points, mesh frame.
/// - `out`: #Q results (4π times the winding number).
/// - `stack`: reusable traversal stack of (node, lane mask).
pub(crate) fn fast_solid_angle_sums(
    bvh: &TriangleBvh,
    nodes: &FastNodes,
    qs: &[V3],
    out: &mut [f64],
    stack: &mut Vec<(u32, LaneMask)>,
) {
    debug_assert_eq!(qs.len(), out.len());
    #[cfg(target_arch = "x86_64")]
    {
        match simd_level() {
            Simd::Avx512 => {
                for (q, o) in qs.chunks(LANES_AVX512).zip(out.chunks_mut(LANES_AVX512)) {
                    // SAFETY: the CPU supports AVX-512F/VL/DQ (checked at run time). As
                    // with AVX2 below, only the vector width changes.
                    unsafe { packet_avx512(bvh, nodes, q, o, stack) };
                }
                return;
            }
            Simd::Avx2 => {
                for (q, o) in qs.chunks(LANES).zip(out.chunks_mut(LANES)) {
                    // SAFETY: the CPU supports AVX2 (checked at run time). AVX2 changes
                    // only the vector width: IEEE operations round lane by lane exactly
                    // as with SSE2, and no fused multiply-add is enabled (Rust never
                    // contracts a * b + c), so the bits are the same.
                    unsafe { packet_avx2(bvh, nodes, q, o, stack) };
                }
                return;
            }
            Simd::Sse2 => {}
        }
    }
    for (q, o) in qs.chunks(LANES).zip(out.chunks_mut(LANES)) {
        packet::<LANES>(bvh, nodes, q, o, stack);
    }
}

/// The widest vector instructions the packet traversal may use on this CPU.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Simd {
    Avx512,
    Avx2,
    Sse2,
}

/// Detected once per process. `VORONOI_FIT_SIMD=avx2` or `=sse2` caps it (for
/// benchmarking the narrower paths and for tests that compare them).
#[cfg(target_arch = "x86_64")]
pub(crate) fn simd_level() -> Simd {
    use std::sync::OnceLock;
    static LEVEL: OnceLock<Simd> = OnceLock::new();
    *LEVEL.get_or_init(|| {
        // Widest first; a cap (any other value is ignored) removes the wider levels.
        let allowed: &[Simd] = match std::env::var("VORONOI_FIT_SIMD").as_deref() {
            Ok("sse2") => &[Simd::Sse2],
            Ok("avx2") => &[Simd::Avx2, Simd::Sse2],
            _ => &[Simd::Avx512, Simd::Avx2, Simd::Sse2],
        };
        allowed.iter().copied().find(|&level| simd_supported(level)).unwrap_or(Simd::Sse2)
    })
}

/// Name of the packet path the fast winding number uses in this process (`"avx512"`,
/// `"avx2"` or `"sse2"`), for timing reports.
pub fn simd_path() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        match simd_level() {
            Simd::Avx512 => "avx512",
            Simd::Avx2 => "avx2",
            Simd::Sse2 => "sse2",
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        "portable"
    }
}

/// Whether this CPU has the features `level`'s packet function is compiled for.
#[cfg(target_arch = "x86_64")]
fn simd_supported(level: Simd) -> bool {
    match level {
        Simd::Avx512 => {
            std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl")
                && std::arch::is_x86_feature_detected!("avx512dq")
                && std::arch::is_x86_feature_detected!("avx2")
        }
        Simd::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
        Simd::Sse2 => true,
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2")]
unsafe fn packet_avx512(
    bvh: &TriangleBvh,
    nodes: &FastNodes,
    qs: &[V3],
    out: &mut [f64],
    stack: &mut Vec<(u32, LaneMask)>,
) {
    packet::<LANES_AVX512>(bvh, nodes, qs, out, stack)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn packet_avx2(
    bvh: &TriangleBvh,
    nodes: &FastNodes,
    qs: &[V3],
    out: &mut [f64],
    stack: &mut Vec<(u32, LaneMask)>,
) {
    packet::<LANES>(bvh, nodes, qs, out, stack)
}

/// One packet of at most `L` (≤ 32) queries (see [`fast_solid_angle_sums`]).
#[inline(always)]
fn packet<const L: usize>(
    bvh: &TriangleBvh,
    nodes: &FastNodes,
    qs: &[V3],
    out: &mut [f64],
    stack: &mut Vec<(u32, LaneMask)>,
) {
    let hot = &nodes.hot[..];
    let moments = &nodes.moments[..];
    let corners = &bvh.corners[..];
    let n = qs.len().min(L);
    if n == 0 {
        return;
    }
    // Unused lanes repeat the first query and are masked off.
    let mut qx = [qs[0][0]; L];
    let mut qy = [qs[0][1]; L];
    let mut qz = [qs[0][2]; L];
    for (i, q) in qs.iter().enumerate().take(n) {
        qx[i] = q[0];
        qy[i] = q[1];
        qz[i] = q[2];
    }
    const { assert!(L <= LaneMask::BITS as usize, "one mask bit per lane") };
    let all: LaneMask = if n == LaneMask::BITS as usize { LaneMask::MAX } else { (1 << n) - 1 };
    let mut sum = [0.0f64; L];
    stack.clear();
    stack.push((0, all));
    while let Some((node, mask)) = stack.pop() {
        let h = &hot[node as usize];
        let cf = h.center_far;
        let mut rx = [0.0; L];
        let mut ry = [0.0; L];
        let mut rz = [0.0; L];
        let mut rho2 = [0.0; L];
        let mut far: LaneMask = 0;
        for i in 0..L {
            rx[i] = cf[0] - qx[i];
            ry[i] = cf[1] - qy[i];
            rz[i] = cf[2] - qz[i];
            rho2[i] = rx[i] * rx[i] + ry[i] * ry[i] + rz[i] * rz[i];
            far |= ((rho2[i] > cf[3]) as LaneMask) << i;
        }
        far &= mask;
        if far != 0 {
            let m = &moments[node as usize];
            if far.count_ones() >= 3 {
                // All lanes in one loop; lanes that did not accept add nothing (their
                // value may be inf or NaN at ρ = 0, so it is selected away, not scaled).
                for i in 0..L {
                    let v = m.eval([rx[i], ry[i], rz[i]], rho2[i]);
                    sum[i] += if far >> i & 1 == 1 { v } else { 0.0 };
                }
            } else {
                let mut bits = far;
                while bits != 0 {
                    let i = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    sum[i] += m.eval([rx[i], ry[i], rz[i]], rho2[i]);
                }
            }
        }
        let near = mask & !far;
        if near == 0 {
            continue;
        }
        if h.link[1] != u32::MAX {
            let tris = &corners[h.link[0] as usize..h.link[1] as usize];
            if near.count_ones() >= 3 {
                for t in tris {
                    let w = solid_angle_lanes(&qx, &qy, &qz, t[0], t[1], t[2]);
                    for i in 0..L {
                        sum[i] += if near >> i & 1 == 1 { w[i] } else { 0.0 };
                    }
                }
                continue;
            }
            let mut bits = near;
            while bits != 0 {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let q = [qx[i], qy[i], qz[i]];
                for t in tris {
                    sum[i] += solid_angle(q, t[0], t[1], t[2]);
                }
            }
        } else {
            let l = h.link[0];
            stack.push((l + 1, near));
            stack.push((l, near));
        }
    }
    out[..n].copy_from_slice(&sum[..n]);
}

/// Work done by one fast query: (nodes visited, expansions evaluated, exact triangles).
pub(crate) fn fast_traversal_counts(bvh: &TriangleBvh, nodes: &FastNodes, q: V3, stack: &mut Vec<u32>) -> [u64; 3] {
    stack.clear();
    stack.push(0);
    let mut counts = [0u64; 3];
    while let Some(n) = stack.pop() {
        counts[0] += 1;
        let cf = nodes.hot[n as usize].center_far;
        let r = sub([cf[0], cf[1], cf[2]], q);
        if dot(r, r) > cf[3] {
            counts[1] += 1;
        } else if bvh.is_leaf(n) {
            let [lo, hi] = bvh.range[n as usize];
            counts[2] += (hi - lo) as u64;
        } else {
            let l = bvh.left_child(n);
            stack.push(l + 1);
            stack.push(l);
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::winding::exact::brute_force_solid_angle_sum;

    /// A deterministic curved patch of triangles inside the unit ball.
    fn patch() -> Vec<[V3; 3]> {
        let mut tris = Vec::new();
        let n = 6;
        let f = |i: usize, j: usize| {
            let x = i as f64 / n as f64 * 1.2 - 0.6;
            let y = j as f64 / n as f64 * 1.2 - 0.6;
            [x, y, 0.3 * (2.0 * x).sin() * (1.0 + y) + 0.1 * y * y]
        };
        for i in 0..n {
            for j in 0..n {
                tris.push([f(i, j), f(i + 1, j), f(i + 1, j + 1)]);
                tris.push([f(i, j), f(i + 1, j + 1), f(i, j + 1)]);
            }
        }
        tris
    }

    /// Every packet width and instruction set the dispatcher may pick (16 lanes in plain
    /// code and with AVX2, 32 lanes with AVX-512, each run when the CPU has it) gives the
    /// one-query traversal's bits, including partial packets and queries on vertices.
    #[test]
    fn every_packet_path_equals_one_query_at_a_time_bit_for_bit() {
        let tris = patch();
        let bvh = crate::bvh::build_triangle_bvh(&tris, crate::config::BvhPreset::Medium, 2, 8);
        let nodes = build_fast_nodes(&bvh, 2.5);
        let mut state = 7u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 1.6 - 0.8
        };
        let mut qs: Vec<V3> = (0..1_037).map(|_| [next(), next(), 0.3 * next()]).collect();
        qs.extend(tris.iter().step_by(5).map(|t| t[1]));
        let mut stack = Vec::new();
        let one: Vec<f64> = qs.iter().map(|q| fast_solid_angle_sum(&bvh, &nodes, *q, &mut stack)).collect();
        let check = |name: &str, got: &[f64]| {
            for (i, (a, b)) in one.iter().zip(got).enumerate() {
                assert!(a.to_bits() == b.to_bits() || (*a == 0.0 && *b == 0.0), "{name}, query {i}: {a:e} vs {b:e}");
            }
        };
        let mut packets = Vec::new();
        let mut out = vec![0.0; qs.len()];
        for (q, o) in qs.chunks(LANES).zip(out.chunks_mut(LANES)) {
            packet::<LANES>(&bvh, &nodes, q, o, &mut packets);
        }
        check("plain", &out);
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                let mut out = vec![0.0; qs.len()];
                for (q, o) in qs.chunks(LANES).zip(out.chunks_mut(LANES)) {
                    // SAFETY: AVX2 checked above.
                    unsafe { packet_avx2(&bvh, &nodes, q, o, &mut packets) };
                }
                check("avx2", &out);
            }
            if simd_supported(Simd::Avx512) {
                let mut out = vec![0.0; qs.len()];
                for (q, o) in qs.chunks(LANES_AVX512).zip(out.chunks_mut(LANES_AVX512)) {
                    // SAFETY: AVX-512F/VL/DQ checked above.
                    unsafe { packet_avx512(&bvh, &nodes, q, o, &mut packets) };
                }
                check("avx512", &out);
            }
        }
        let mut out = vec![0.0; qs.len()];
        fast_solid_angle_sums(&bvh, &nodes, &qs, &mut out, &mut packets);
        check("dispatched", &out);
    }

    #[test]
    fn packed_evaluation_equals_the_tensor_formula() {
        let node = node_expansion(&patch(), 2.0);
        let packed = PackedMoments::from(&node.moments);
        for q in [[3.0, -1.0, 2.0], [0.1, 4.0, -0.3], [-5.0, -5.0, 5.0], [0.0, 0.2, 2.5]] {
            let r = sub(node.center, q);
            let a = node.eval(r, dot(r, r));
            let b = packed.eval(r, dot(r, r));
            assert!((a - b).abs() <= 1e-13 * a.abs().max(1e-3), "{q:?}: {a} vs {b}");
        }
    }

    #[test]
    fn expansion_error_decays_like_order_three() {
        // Truncating after order 2 leaves an error ∝ ρ⁻⁵ (contribution ρ⁻² times (R/ρ)³),
        // so doubling the distance must divide the error by about 32; a wrong order-2 term
        // would only give 16.
        let tris = patch();
        let node = node_expansion(&tris, 2.0);
        let dir = [0.48, -0.6, 0.64];
        let mut errors = Vec::new();
        for rho in [8.0, 16.0, 32.0] {
            let q = sub(node.center, scale(dir, rho));
            let r = sub(node.center, q);
            let approx = node.eval(r, dot(r, r));
            let exact = brute_force_solid_angle_sum(&tris, q);
            errors.push((approx - exact).abs());
        }
        let ratio1 = errors[0] / errors[1];
        let ratio2 = errors[1] / errors[2];
        assert!(ratio1 > 26.0 && ratio2 > 26.0, "{errors:?} {ratio1} {ratio2}");
    }
}
