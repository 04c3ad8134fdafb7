//! The mesh rasterizer: coverage of a known mesh, determinism, empty and degenerate
//! meshes, PNG output. Set `VF_RASTER_OUT=DIR` to keep the pictures for a look.

use mesh_io::TriMesh;
use plot::raster3d::{render, Image, Model, Options, Up, View, CRUST_COLOR, INPUT_COLOR};

fn cube() -> TriMesh {
    let positions = (0..8).map(|i| [f64::from(i & 1), f64::from((i >> 1) & 1), f64::from((i >> 2) & 1)]).collect();
    // Counter-clockwise seen from outside.
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let triangles = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    TriMesh { positions, triangles }
}

fn bunny() -> TriMesh {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/bunny.obj");
    mesh_io::read_mesh(&root).expect("bunny")
}

/// Pixels of the drawing area of cell (`row`, `col`) that differ from the background
/// (not greyish-blue light): the fraction covered by the mesh.
fn coverage(img: &Image, opts: &Options, row: u32, col: u32) -> f64 {
    let (cw, ch) = opts.cell;
    let title = if opts.title.is_empty() { 0 } else { 28 };
    let (x0, y0) = (col * cw + 2, title + row * ch + 22);
    let (mut hit, mut all) = (0usize, 0usize);
    for y in y0..title + (row + 1) * ch - 2 {
        for x in x0..(col + 1) * cw - 2 {
            let [r, g, b] = img.pixel(x, y);
            all += 1;
            // The background is a light grey-blue gradient: all channels ≥ 220, blue highest.
            if !(r >= 218 && g >= 218 && b >= 218) {
                hit += 1;
            }
        }
    }
    hit as f64 / all as f64
}

fn keep(name: &str, img: &Image) {
    if let Ok(dir) = std::env::var("VF_RASTER_OUT") {
        std::fs::create_dir_all(&dir).unwrap();
        img.write_png(&std::path::Path::new(&dir).join(name)).unwrap();
    }
}

#[test]
fn cube_covers_a_plausible_share_from_every_view() {
    let cube = cube();
    let opts = Options { cell: (200, 200), ..Default::default() };
    let img = render(&[Model { label: "cube".into(), mesh: &cube, color: CRUST_COLOR }], &opts).unwrap();
    assert_eq!((img.width, img.height), (600, 200));
    assert_eq!(img.rgb.len(), 600 * 200 * 3);
    for col in 0..3 {
        let c = coverage(&img, &opts, 0, col);
        // A unit cube framed with 6% margins: its silhouette fills 40–90% of the cell.
        assert!((0.35..0.9).contains(&c), "view {col}: coverage {c}");
    }
    keep("cube.png", &img);
}

#[test]
fn front_view_of_a_square_is_its_area() {
    // A square facing the camera (view from +Z, no elevation) fills the framed area:
    // (1 − 2·6%)² of the drawing area.
    let sq = TriMesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    let opts = Options { views: vec![View::new("front", 0.0, 0.0)], cell: (200, 220), ..Default::default() };
    let img = render(&[Model { label: "square".into(), mesh: &sq, color: INPUT_COLOR }], &opts).unwrap();
    let c = coverage(&img, &opts, 0, 0);
    // The square spans 0.88 × 200 = 176 pixels; the counted area is 196 × 196.
    let want = (176.0f64 / 196.0).powi(2);
    assert!((c - want).abs() < 0.03, "coverage {c}, want about {want}");
    // Seen from behind, the same square is drawn in the back-face colour.
    let opts_back = Options { views: vec![View::new("back", 180.0, 0.0)], ..opts.clone() };
    let back = render(&[Model { label: "square".into(), mesh: &sq, color: INPUT_COLOR }], &opts_back).unwrap();
    let [r, g, b] = back.pixel(100, 20 + 100);
    assert!(r > g && g > b, "back face colour, got {r},{g},{b}");
}

#[test]
fn bunny_input_and_crust_rows_are_deterministic() {
    let bunny = bunny();
    let models = [
        Model { label: "input".into(), mesh: &bunny, color: INPUT_COLOR },
        Model { label: "crust".into(), mesh: &bunny, color: CRUST_COLOR },
    ];
    let opts = Options { title: "bunny: input and crust".into(), ..Default::default() };
    let a = render(&models, &opts).unwrap();
    let b = render(&models, &opts).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.to_png().unwrap(), b.to_png().unwrap());
    assert_eq!((a.width, a.height), (1200, 28 + 800));
    for row in 0..2 {
        for col in 0..3 {
            let c = coverage(&a, &opts, row, col);
            assert!((0.15..0.8).contains(&c), "cell {row},{col}: coverage {c}");
        }
    }
    keep("bunny.png", &a);
    let z = Options { up: Up::Z, ..opts };
    keep("bunny_zup.png", &render(&models, &z).unwrap());
}

#[test]
fn empty_and_degenerate_meshes_give_valid_blank_pictures() {
    let empty = TriMesh::default();
    let point = TriMesh { positions: vec![[1.0, 2.0, 3.0]; 3], triangles: vec![[0, 1, 2]] };
    let bad = TriMesh {
        positions: vec![[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, f64::INFINITY]],
        triangles: vec![[0, 1, 2], [0, 1, 7]],
    };
    let line =
        TriMesh { positions: vec![[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]], triangles: vec![[0, 1, 2]] };
    let huge = TriMesh {
        positions: vec![[-1e300, 0.0, 0.0], [1e300, 0.0, 0.0], [0.0, 1e300, 0.0]],
        triangles: vec![[0, 1, 2]],
    };
    let opts = Options { cell: (100, 100), ..Default::default() };
    for (name, m) in [("empty", &empty), ("point", &point), ("nan", &bad), ("line", &line), ("huge", &huge)] {
        let img = render(&[Model { label: name.into(), mesh: m, color: CRUST_COLOR }], &opts).unwrap();
        assert_eq!(img.rgb.len(), 300 * 100 * 3, "{name}");
        let png = img.to_png().unwrap();
        assert_eq!(&png[1..4], b"PNG", "{name}");
        if name != "huge" {
            // Only the grey note "no triangles to draw" (or nothing) is in the cell.
            assert!(coverage(&img, &opts, 0, 0) < 0.03, "{name} drew something");
        }
    }
    // No model, no view or an absurd size is an error, not a panic.
    assert!(render(&[], &opts).is_err());
    let m = [Model { label: "e".into(), mesh: &empty, color: CRUST_COLOR }];
    assert!(render(&m, &Options { views: vec![], ..opts.clone() }).is_err());
    assert!(render(&m, &Options { cell: (10, 10), ..opts.clone() }).is_err());
    assert!(render(&m, &Options { cell: (100_000, 100), ..opts }).is_err());
}

#[test]
fn write_png_is_atomic_and_readable() {
    let dir = tempfile::tempdir().unwrap();
    let cube = cube();
    let img = render(
        &[Model { label: "cube".into(), mesh: &cube, color: CRUST_COLOR }],
        &Options { cell: (100, 100), ..Default::default() },
    )
    .unwrap();
    let path = dir.path().join("cube.png");
    img.write_png(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(bytes, img.to_png().unwrap());
    // Only the PNG is left in the folder (no temporary file).
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    // An unwritable target is an error and leaves nothing.
    assert!(img.write_png(&dir.path().join("missing/cube.png")).is_err());
}

/// Time for a large mesh (not run by default): `VF_RASTER_MESH=big.ply cargo test -p plot
/// --profile ci --test raster3d -- --ignored --nocapture`.
#[test]
#[ignore]
fn large_mesh_timing() {
    let Ok(path) = std::env::var("VF_RASTER_MESH") else { return };
    let mesh = mesh_io::read_mesh(std::path::Path::new(&path)).unwrap();
    let t = std::time::Instant::now();
    let img = render(&[Model { label: "mesh".into(), mesh: &mesh, color: CRUST_COLOR }], &Options::default()).unwrap();
    println!("{} triangles: {:.2} s for {}x{}", mesh.triangles.len(), t.elapsed().as_secs_f64(), img.width, img.height);
    keep("large.png", &img);
}
