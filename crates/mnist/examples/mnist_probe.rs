//! One method trained on the first IMAGES training digits for EPOCHS epochs, then its
//! training curve and its table row on test digits 1–1,000 (or, for fewer than 100
//! images, on the training digits themselves): the runs behind the β and
//! signed-distance ablation (`benches/mnist_ablation.sh`).
//!
//! `cargo run --release -p vf-mnist --example mnist_probe -- METHOD IMAGES EPOCHS [LR]
//! [BATCH] [W_REC,W_BOUNDS,W_SD,W_CENTROIDAL] [BETA] [BETA_START]` (run from the
//! repository root: it reads ../shared/mnist).
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use mnist::{eval, idx, Method, TrainSettings, TrainState};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let method: Method = a[1].parse().unwrap();
    let n: usize = a[2].parse().unwrap();
    let epochs: usize = a[3].parse().unwrap();
    let dir = std::path::Path::new("../shared/mnist");
    let (i, l) = idx::find_set(dir, false).unwrap();
    let train = idx::read_set(&i, &l).unwrap();
    let (i, l) = idx::find_set(dir, true).unwrap();
    let test = idx::read_set(&i, &l).unwrap();
    let mut s = TrainSettings { epochs, train_images: n, ..TrainSettings::full() };
    if a.len() > 4 {
        s.lr = a[4].parse().unwrap();
    }
    if a.len() > 5 {
        s.batch = a[5].parse().unwrap();
    }
    if a.len() > 6 {
        let w: Vec<f64> = a[6].split(',').map(|x| x.parse().unwrap()).collect();
        s.voronoi.reconstruction = w[0];
        s.voronoi.bounds = w[1];
        s.voronoi.signed_distance = w[2];
        s.voronoi.centroidal = w[3];
    }
    if a.len() > 7 {
        s.voronoi.beta = a[7].parse().unwrap();
    }
    if a.len() > 8 {
        s.beta_start = Some(a[8].parse().unwrap());
    }
    let mut st = TrainState::new(method, 784, s);
    let t = Instant::now();
    let stop = AtomicBool::new(false);
    st.run(&train, None, 0, &stop, |_| {}).unwrap();
    let secs = t.elapsed().as_secs_f64();
    for c in &st.curve {
        println!("epoch {} loss {:.4} parts {:?} t {:.1}", c.epoch, c.loss, c.parts, c.seconds);
    }
    println!("train {:.1} s, {:.0} images/s", secs, (n * epochs) as f64 / secs);
    if n < 100 {
        let im = train.images.image(0);
        let z = st.model.encode(&[im]);
        let sites = st.model.decode_sites(&z).unwrap().remove(0);
        let d = mnist::digit::Digit::new(im, 28, 28);
        let inside_ok = sites[..64].iter().filter(|p| d.inside(**p)).count();
        let outside_ok = sites[64..].iter().filter(|p| !d.inside(**p)).count();
        println!(
            "inside sites in digit {inside_ok}/64, outside sites outside {outside_ok}/64; first sites {:?}",
            &sites[..3]
        );
    }
    let r = if n < 100 { eval::evaluate(&st.model, &train, n, n) } else { eval::evaluate(&st.model, &test, 1000, 200) };
    println!("{}", eval::table_markdown(&[r]));
}
