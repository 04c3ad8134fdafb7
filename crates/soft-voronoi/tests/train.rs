//! Training: regulariser gradients against finite differences, bit-identical resume and
//! thread-count independence, and that training on a sphere improves the fit and leaves a
//! watertight crust.

use soft_voronoi::losses::{self, SiteGraph, Solid};
use soft_voronoi::{checkpoint, classify, Init, Sphere, TrainConfig, TrainError, TrainState, Trainer, TrainingData};
use vf_common::rng::{ChunkRng, Stream};

const SPHERE: Sphere = Sphere { center: [0.5, 0.5, 0.5], radius: 0.35 };

/// Uniform and near-surface samples of the sphere, labelled analytically, with surface
/// points and normals.
fn sphere_data(n: usize, seed: u64) -> TrainingData {
    let mut rng = ChunkRng::for_chunk(seed, Stream::Test, 11);
    let mut points = Vec::with_capacity(n);
    let mut surface = Vec::new();
    let mut normals = Vec::new();
    for i in 0..n {
        let dir = loop {
            let d = [0, 1, 2].map(|_| 2.0 * rng.uniform() - 1.0);
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if l > 1e-3 && l <= 1.0 {
                break d.map(|x| x / l);
            }
        };
        let s = [0, 1, 2].map(|c| SPHERE.center[c] + SPHERE.radius * dir[c]);
        surface.push(s);
        normals.push(dir);
        if i % 2 == 0 {
            points.push([rng.uniform(), rng.uniform(), rng.uniform()]);
        } else {
            let sigma = if i % 4 == 1 { 0.01 } else { 0.003 };
            points.push([0, 1, 2].map(|c| s[c] + sigma * rng.normal()));
        }
    }
    let occupancy = points.iter().map(|&p| SPHERE.contains(p)).collect();
    TrainingData { points, occupancy, surface, normals }
}

fn small_config(init: Init) -> TrainConfig {
    let mut c = TrainConfig::default_for(256);
    c.init = init;
    c.steps = 40;
    c.batch = 3000;
    c.lr = 2e-4;
    c.lr_final = 1e-5;
    c.beta_start = Some(2000.0);
    c.weights.signed_distance = 1e-2;
    c.weights.centroidal = 1e-2;
    c.refresh_every = 7;
    c.seed = 9;
    c
}

fn run(config: TrainConfig, data: &TrainingData, steps: usize) -> TrainState {
    let mut t = Trainer::new(config, data, &SPHERE).unwrap();
    for _ in 0..steps {
        t.step().unwrap();
    }
    t.state().clone()
}

fn bits(sites: &[[f64; 3]]) -> Vec<u64> {
    sites.iter().flatten().map(|x| x.to_bits()).collect()
}

#[test]
fn resume_from_checkpoint_is_bit_identical() {
    let data = sphere_data(20_000, 1);
    for init in [Init::Surface, Init::Paper, Init::Samples] {
        let config = small_config(init);
        let full = run(config.clone(), &data, 40);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ck.npz");
        let half = run(config.clone(), &data, 17);
        checkpoint::write(&path, &half, "{\"note\": 1}").unwrap();
        let (state, ctx) = checkpoint::read(&path).unwrap();
        assert_eq!(ctx, "{\"note\": 1}");
        assert_eq!(state, half, "the checkpoint round trip changed the state");
        let mut t = Trainer::resume(state, &data, &SPHERE, "ck.npz").unwrap();
        while !t.is_done() {
            t.step().unwrap();
        }
        assert_eq!(bits(&t.state().sites), bits(&full.sites), "{init:?}: resumed sites differ");
        assert_eq!(t.state(), &full, "{init:?}: resumed state differs");
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let data = sphere_data(20_000, 2);
    let config = small_config(Init::Surface);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let three = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
    let a = one.install(|| run(config.clone(), &data, 25));
    let b = three.install(|| run(config.clone(), &data, 25));
    assert_eq!(bits(&a.sites), bits(&b.sites));
    assert_eq!(a.history, b.history);
}

#[test]
fn resume_refuses_other_data_and_bad_checkpoints() {
    let data = sphere_data(5_000, 3);
    let other = sphere_data(5_000, 4);
    let state = run(small_config(Init::Surface), &data, 3);
    match Trainer::resume(state, &other, &SPHERE, "x.npz") {
        Err(TrainError::Checkpoint { message, .. }) => assert!(message.contains("different samples"), "{message}"),
        Err(e) => panic!("wrong error {e}"),
        Ok(_) => panic!("resumed on other data"),
    }
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in [("empty.npz", &b""[..]), ("junk.npz", &b"PK\x03\x04 not really"[..])] {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        let e = checkpoint::read(&p).unwrap_err().to_string();
        assert!(e.contains(name), "{e}");
    }
}

#[test]
fn training_improves_the_sphere_and_the_crust_is_watertight() {
    let data = sphere_data(200_000, 5);
    let fresh = sphere_data(100_000, 6);
    for (init, steps) in [(Init::Surface, 150), (Init::Paper, 1000)] {
        let mut c = if init == Init::Paper { TrainConfig::paper(512) } else { TrainConfig::default_for(512) };
        c.steps = steps;
        c.batch = 8192;
        c.seed = 3;
        let mut t = Trainer::new(c, &data, &SPHERE).unwrap();
        let error = |t: &Trainer| {
            let (s, l, _) = t.final_sites();
            let pred = classify(&s, &l, &fresh.points);
            pred.iter().zip(&fresh.occupancy).filter(|(a, b)| a != b).count() as f64 / fresh.points.len() as f64
        };
        let ball = 4.0 / 3.0 * std::f64::consts::PI * 0.35f64.powi(3);
        let volume_error = |t: &Trainer| {
            let (sites, labels, _) = t.final_sites();
            let crust = crust::Crust::extract(&sites, &labels, &crust::CrustConfig::default()).unwrap();
            let check = crust::check::check_crust(&crust.mesh).unwrap();
            assert!(check.report.is_closed && check.report.is_manifold);
            (check.report.signed_volume - ball).abs() / ball
        };
        let (before, vol_before) = (error(&t), volume_error(&t));
        while !t.is_done() {
            t.step().unwrap();
        }
        let (after, vol_after) = (error(&t), volume_error(&t));
        eprintln!("{init:?}: misclassification {before:.4} -> {after:.4}, crust volume error {vol_before:.4} -> {vol_after:.4}");
        assert!(after < 0.8 * before, "{init:?}: misclassification {before} -> {after}");
        assert!(vol_after < vol_before, "{init:?}: crust volume error {vol_before} -> {vol_after}");
        if init == Init::Surface {
            assert!(vol_after < 0.03, "{init:?}: crust volume error {vol_after}");
        }
    }
}

fn random_sites(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = ChunkRng::for_chunk(seed, Stream::Test, 12);
    (0..n).map(|_| [rng.uniform(), rng.uniform(), rng.uniform()]).collect()
}

/// Central differences of `f` at `sites` against `grad`, coordinate by coordinate.
fn fd_check(sites: &[[f64; 3]], grad: &[[f64; 3]], f: impl Fn(&[[f64; 3]]) -> f64, tol: f64) {
    let h = 1e-6;
    for i in 0..grad.len() {
        for c in 0..3 {
            let mut p = sites.to_vec();
            p[i][c] += h;
            let mut m = sites.to_vec();
            m[i][c] -= h;
            let fd = (f(&p) - f(&m)) / (2.0 * h);
            assert!((fd - grad[i][c]).abs() <= tol * (1.0 + fd.abs()), "site {i}.{c}: fd {fd} vs {}", grad[i][c]);
        }
    }
}

#[test]
fn regulariser_gradients_equal_finite_differences() {
    let mut sites = random_sites(60, 1);
    sites.extend([[-0.2, 0.5, 0.5], [0.5, 1.3, 0.5], [0.5, 0.5, -0.01]]);
    let k = sites.len() - 5; // the last 5 are fixed (boundary-like) sites
    let inside: Vec<bool> = (0..sites.len()).map(|i| i % 3 == 0).collect();
    // Bounds.
    let mut g = vec![[0.0; 3]; sites.len()];
    losses::bounds(&sites, 2.0, &mut g);
    fd_check(&sites, &g, |s| 2.0 * losses::bounds(s, 1.0, &mut vec![[0.0; 3]; s.len()]), 1e-6);
    // Signed distance, to the sphere (sides and closest points recomputed: exact gradient).
    let mut g = vec![[0.0; 3]; k];
    losses::signed_distance(&SPHERE, &sites[..k], &inside[..k], 3.0, &mut g);
    assert!(g.iter().flatten().any(|x| *x != 0.0));
    fd_check(
        &sites[..k],
        &g,
        |s| 3.0 * losses::signed_distance(&SPHERE, s, &inside[..k], 1.0, &mut vec![[0.0; 3]; s.len()]),
        1e-5,
    );
    // Centroidal, on a fixed graph, trainable sites only.
    let graph = SiteGraph::delaunay(&sites).unwrap();
    let mut g = vec![[0.0; 3]; k];
    losses::centroidal(&graph, &sites, 0.5, &mut g);
    let f = |s: &[[f64; 3]]| {
        let mut all = s.to_vec();
        all.extend_from_slice(&sites[k..]);
        0.5 * losses::centroidal(&graph, &all, 1.0, &mut vec![[0.0; 3]; k])
    };
    fd_check(&sites[..k], &g, f, 1e-6);
}

#[test]
fn delaunay_graph_is_symmetric_and_covers_duplicates() {
    let mut sites = random_sites(300, 7);
    sites.push(sites[10]);
    let g = SiteGraph::delaunay(&sites).unwrap();
    assert_eq!(g.num_sites(), sites.len());
    for i in 0..sites.len() {
        for &j in g.row(i) {
            if j as usize != 300 && i != 300 {
                assert!(g.row(j as usize).contains(&(i as u32)), "edge {i}-{j} not symmetric");
            }
        }
    }
    assert_eq!(g.row(300), g.row(10));
}

#[test]
fn invalid_settings_are_refused_with_their_name() {
    let data = sphere_data(1000, 8);
    let mut c = TrainConfig::default_for(100);
    c.lr = f64::NAN;
    assert!(Trainer::new(c, &data, &SPHERE).err().unwrap().to_string().contains("learning rate"));
    let mut c = TrainConfig::default_for(100);
    c.weights.centroidal = -1.0;
    assert!(Trainer::new(c, &data, &SPHERE).err().unwrap().to_string().contains("centroidal"));
    let c = TrainConfig::default_for(5000);
    assert!(Trainer::new(c, &data, &SPHERE).is_err(), "more sites than surface samples must fail");
    let mut bad = data.clone();
    bad.points[3][1] = f64::INFINITY;
    assert!(Trainer::new(TrainConfig::default_for(100), &bad, &SPHERE).err().unwrap().to_string().contains("point 3"));
    let located = SPHERE.locate(&[[0.5, 0.5, 0.9]]);
    assert!(!located[0].inside);
}

/// The best iterate by the fixed evaluation batch is what `final_sites` returns; measuring
/// it does not change the trajectory; with selection off the last iterate is returned.
#[test]
fn the_best_iterate_is_kept_and_does_not_change_the_run() {
    let data = sphere_data(40_000, 7);
    // Mirrored pairs start close to the sphere; a constant learning rate far too large for
    // them (5e-3, a quarter of their spacing per step) makes the loss worse, so the
    // initialisation must be the best iterate.
    let mut c = TrainConfig::default_for(512);
    c.steps = 30;
    c.batch = 4096;
    c.lr = 5e-3;
    c.lr_final = 5e-3;
    c.select_every = 5;
    c.selection_batch = 20_000;
    c.seed = 4;
    let mut t = Trainer::new(c.clone(), &data, &SPHERE).unwrap();
    let init = t.state().sites.clone();
    while !t.is_done() {
        t.step().unwrap();
    }
    let best = t.state().best.clone().expect("a best iterate");
    assert_eq!(best.step, 0, "a run that only got worse kept step {}", best.step);
    let (sites, _, _) = t.final_sites();
    assert_eq!(bits(&sites[..512]), bits(&init[..512]));
    assert_ne!(bits(&t.state().sites[..512]), bits(&init[..512]));

    // A sound rate: the kept iterate is a later one, and it is the sites that a run without
    // selection has after that many steps (selection only watches).
    let mut good = c.clone();
    good.lr = 1e-4;
    good.lr_final = 1e-6;
    good.init = Init::Surface;
    let mut t = Trainer::new(good.clone(), &data, &SPHERE).unwrap();
    while !t.is_done() {
        t.step().unwrap();
    }
    let best = t.state().best.clone().unwrap();
    assert!(best.step > 0 && (best.step % 5 == 0 || best.step == 30), "kept step {}", best.step);
    let plain = run(TrainConfig { select_every: 0, ..good.clone() }, &data, best.step);
    assert!(plain.best.is_none());
    assert_eq!(bits(&best.sites), bits(&plain.sites[..512]));
    let (sites, _, _) = t.final_sites();
    assert_eq!(bits(&sites[..512]), bits(&best.sites));
    let full_plain = run(TrainConfig { select_every: 0, ..good }, &data, 30);
    let (last, _, _) = Trainer::resume(full_plain.clone(), &data, &SPHERE, "-").unwrap().final_sites();
    assert_eq!(bits(&last), bits(&full_plain.sites), "selection off: the last iterate");
}
