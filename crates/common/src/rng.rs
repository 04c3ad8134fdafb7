//! Small, fully specified random number generators so samples are reproducible across
//! platforms, crate versions and thread counts, and the table of the workspace's random
//! streams.
//!
//! - SplitMix64 (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
//!   OOPSLA 2014) derives independent seeds and, as [`SplitMix64`], is the small sequential
//!   generator of the MLP baselines and of Delaunay's insertion order.
//! - xoshiro256++ (Blackman and Vigna, "Scrambled linear pseudorandom number generators",
//!   ACM TOMS 2021) generates each chunk's stream ([`ChunkRng`]).
//!
//! Every random draw in the workspace names its [`Stream`]; the numbers below are the ones
//! the crates used before they shared this table, so seeded results are unchanged.

/// The random streams of the workspace. A user seed and a stream give independent
/// sequences; two purposes never share a stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u64)]
pub enum Stream {
    /// occupancy: uniform samples in a box.
    SampleUniform = 1,
    /// occupancy: area-uniform surface samples.
    SampleSurface = 2,
    /// occupancy: near-surface samples (surface point + Gaussian offset).
    SampleNearSurface = 3,
    /// soft-voronoi: the sites' initialisation.
    SitesInit = 101,
    /// soft-voronoi: the training batches.
    TrainBatch = 102,
    /// soft-voronoi: the surface-term batches.
    SurfaceBatch = 103,
    /// soft-voronoi: the fixed evaluation batch that picks the best iterate.
    SelectionBatch = 104,
    /// soft-voronoi: the surface samples of that batch.
    SelectionSurface = 105,
    /// soft-voronoi: the surface batches of the polish (VoroLoss) after training.
    PolishBatch = 106,
    /// study: the sphere's training data.
    StudySphereData = 301,
    /// study: the sphere's Chamfer samples.
    StudyChamfer = 302,
    /// mnist: the networks' weight initialisation.
    MnistInit = 401,
    /// mnist: the order of the training images in each epoch.
    MnistShuffle = 402,
    /// mnist: the training points of each image in each epoch (shared by every method).
    MnistPoints = 403,
    /// mnist: the tSNE's initial embedding.
    MnistTsne = 404,
    /// baselines: the MLP's batch order.
    MlpBatch = 0x0BA7_C4E5,
    /// baselines: the MLP's weight initialisation.
    MlpInit = 0x1417_5EED,
    /// tests and examples: made-up data (the chunk index tells the test's pools apart).
    Test = 0x7E57,
    /// delaunay3: the BRIO shuffle (a fixed seed: the order must not depend on a user seed).
    DelaunayInsertion = 0x5EED_DE1A_0A17,
}

/// Seed offsets: where one run draws two independent pools from the same sampler with the
/// same stream, the second pool's seed is the user seed XOR one of these.
pub mod seed_tweak {
    /// fit: the surface points of the training data (initialisation and surface terms).
    pub const TRAIN_SURFACE: u64 = 0x5151;
    /// fit: the fresh evaluation samples (misclassification).
    pub const EVALUATION: u64 = 0x5eed_e7a1_0000_0001;
}

/// One SplitMix64 step: advances `state` and returns the next output.
#[inline]
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Sequential SplitMix64 generator: one 64-bit state, for short sequential uses.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// The generator for `(seed, stream)`: different streams give independent sequences.
    pub fn new(seed: u64, stream: Stream) -> Self {
        let mut r = SplitMix64(seed ^ (stream as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
        r.next_u64();
        r
    }

    /// The generator started at a raw state (for fixed, seedless orders).
    pub fn from_state(state: u64) -> Self {
        SplitMix64(state)
    }

    /// Next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        splitmix64(&mut self.0)
    }

    /// Uniform f64 in [0, 1) with 53 random bits.
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform integer in `0..n` (`n > 0`), by Lemire's multiply-shift (bias below 2^-32 for
    /// the sizes used here).
    #[inline]
    pub fn below(&mut self, n: usize) -> usize {
        ((self.next_u64() as u128 * n as u128) >> 64) as usize
    }
}

/// xoshiro256++ generator with a cached second Gaussian.
#[derive(Clone, Debug)]
pub struct ChunkRng {
    s: [u64; 4],
    spare_normal: Option<f64>,
}

impl ChunkRng {
    /// The generator for chunk `chunk` of stream `stream` under user seed `seed`.
    ///
    /// Streams separate the samplers (uniform, surface, near-surface) so that they do not
    /// reuse each other's numbers for the same seed.
    pub fn for_chunk(seed: u64, stream: Stream, chunk: u64) -> Self {
        Self::for_raw_stream(seed, stream as u64, chunk)
    }

    fn for_raw_stream(seed: u64, stream: u64, chunk: u64) -> Self {
        let mut sm = seed;
        let a = splitmix64(&mut sm);
        let mut sm = a ^ stream.wrapping_mul(0xD1B5_4A32_D192_ED03);
        let b = splitmix64(&mut sm);
        let mut sm = b ^ chunk.wrapping_mul(0x8CB9_2BA7_2F3D_8DD7);
        let s = [splitmix64(&mut sm), splitmix64(&mut sm), splitmix64(&mut sm), splitmix64(&mut sm)];
        ChunkRng { s, spare_normal: None }
    }

    /// Next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// Uniform f64 in [0, 1) with 53 random bits.
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard normal deviate (Box–Muller, both outputs used).
    #[inline]
    pub fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare_normal.take() {
            return z;
        }
        // u1 in (0, 1] so the logarithm is finite.
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        let r = (-2.0 * u1.ln()).sqrt();
        let theta = 2.0 * std::f64::consts::PI * u2;
        self.spare_normal = Some(r * theta.sin());
        r * theta.cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_matches_reference_values() {
        // Reference outputs of SplitMix64 seeded with 1234567 (Vigna's splitmix64.c).
        let mut s = 1234567u64;
        let got: Vec<u64> = (0..3).map(|_| splitmix64(&mut s)).collect();
        assert_eq!(got, vec![6457827717110365317, 3203168211198807973, 9817491932198370423]);
    }

    #[test]
    fn streams_and_chunks_differ() {
        let a = ChunkRng::for_raw_stream(7, 0, 0).next_u64();
        let b = ChunkRng::for_raw_stream(7, 0, 1).next_u64();
        let c = ChunkRng::for_raw_stream(7, 1, 0).next_u64();
        let d = ChunkRng::for_raw_stream(8, 0, 0).next_u64();
        assert!(a != b && a != c && a != d && b != c);
        assert_eq!(a, ChunkRng::for_raw_stream(7, 0, 0).next_u64());
        assert_eq!(
            ChunkRng::for_chunk(7, Stream::SampleUniform, 0).next_u64(),
            ChunkRng::for_raw_stream(7, 1, 0).next_u64()
        );
    }

    #[test]
    fn streams_are_distinct() {
        use Stream::*;
        let all = [
            SampleUniform,
            SampleSurface,
            SampleNearSurface,
            SitesInit,
            TrainBatch,
            SurfaceBatch,
            SelectionBatch,
            SelectionSurface,
            PolishBatch,
            StudySphereData,
            StudyChamfer,
            MnistInit,
            MnistShuffle,
            MnistPoints,
            MnistTsne,
            MlpBatch,
            MlpInit,
            DelaunayInsertion,
            Test,
        ];
        let set: std::collections::HashSet<u64> = all.iter().map(|&s| s as u64).collect();
        assert_eq!(set.len(), all.len());
    }

    #[test]
    fn splitmix_below_stays_in_range() {
        let mut r = SplitMix64::new(3, Stream::MlpBatch);
        for n in [1usize, 2, 7, 1000] {
            for _ in 0..1000 {
                assert!(r.below(n) < n);
            }
        }
    }

    #[test]
    fn normal_has_unit_variance() {
        let mut r = ChunkRng::for_chunk(1, Stream::SampleSurface, 3);
        let n = 200_000;
        let (mut s1, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let z = r.normal();
            s1 += z;
            s2 += z * z;
        }
        let mean = s1 / n as f64;
        let var = s2 / n as f64 - mean * mean;
        assert!(mean.abs() < 0.01, "{mean}");
        assert!((var - 1.0).abs() < 0.01, "{var}");
    }
}
