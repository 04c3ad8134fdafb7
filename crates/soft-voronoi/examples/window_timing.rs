//! Times the kernel's candidate query on real sites: kiddo nearest + radius query against
//! KnnTree's fused window query, cold and warm-started.
//! `cargo run --release -p soft-voronoi --example window_timing -- SITES.f64`
use std::time::Instant;

use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use soft_voronoi::kernel::{distance, SiteIndex, NO_HINT};
use vf_common::rng::{ChunkRng, Stream};

fn main() {
    let path = std::env::args().nth(1).expect("sites file");
    let bytes = std::fs::read(path).unwrap();
    let f: Vec<f64> = bytes.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect();
    let sites: Vec<[f64; 3]> = f.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let mut rng = ChunkRng::for_chunk(1, Stream::TrainBatch, 0);
    let mut u = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    let n = 16384;
    let mut pts = Vec::new();
    for i in 0..n {
        if i % 2 == 0 {
            pts.push([u(), u(), u()]);
        } else {
            let s = sites[(u() * sites.len() as f64) as usize % sites.len()];
            pts.push([s[0] + 0.01 * (u() - 0.5), s[1] + 0.01 * (u() - 0.5), s[2] + 0.01 * (u() - 0.5)]);
        }
    }
    let window = 30.0 / 10000.0;
    let reps = 20;
    let tree: ImmutableKdTree<f64, u32, 3, 32> = ImmutableKdTree::new_from_slice(&sites);
    let t = Instant::now();
    let mut acc = 0usize;
    for _ in 0..reps {
        for &x in &pts {
            let nn = tree.nearest_one::<SquaredEuclidean>(&x);
            let d = distance(x, sites[nn.item as usize]);
            let r = d + window;
            acc += tree.within_unsorted::<SquaredEuclidean>(&x, r * r * (1.0 + 1e-12)).len();
        }
    }
    println!("kiddo nearest+within: {:.3} us/query ({acc})", t.elapsed().as_secs_f64() * 1e6 / (reps * n) as f64);
    let t = Instant::now();
    let mut acc = 0usize;
    for _ in 0..reps {
        for &x in &pts {
            acc += tree.nearest_one::<SquaredEuclidean>(&x).item as usize;
        }
    }
    println!("kiddo nearest only: {:.3} us/query ({acc})", t.elapsed().as_secs_f64() * 1e6 / (reps * n) as f64);
    let index = SiteIndex::new(&sites);
    let mut out = Vec::new();
    let t = Instant::now();
    let mut acc = 0usize;
    for _ in 0..reps {
        for &x in &pts {
            index.candidates(&sites, x, window, &mut out);
            acc += out.len();
        }
    }
    println!("knn window cold: {:.3} us/query ({acc})", t.elapsed().as_secs_f64() * 1e6 / (reps * n) as f64);
    let mut hints = vec![NO_HINT; n];
    for (x, h) in pts.iter().zip(&mut hints) {
        index.candidates_hinted(&sites, *x, window, h, &mut out);
    }
    let t = Instant::now();
    let mut acc = 0usize;
    for _ in 0..reps {
        for (x, h) in pts.iter().zip(&mut hints) {
            index.candidates_hinted(&sites, *x, window, h, &mut out);
            acc += out.len();
        }
    }
    println!("knn window warm: {:.3} us/query ({acc})", t.elapsed().as_secs_f64() * 1e6 / (reps * n) as f64);
}
