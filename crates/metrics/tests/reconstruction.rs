//! Chamfer, F-score, normal consistency, IoU, validity and the combined report.

mod common;

use mesh_io::shapes::{box_with_hole, icosphere, torus};
use mesh_io::TriMesh;
use metrics::{evaluate, surface_metrics, validity, volumetric_iou, EvalOptions, MetricsError, SurfaceOptions};

#[test]
fn identical_meshes_score_perfectly() {
    let a = torus(1.0, 0.35, 48, 24);
    let m = surface_metrics(&a, &a, &SurfaceOptions::default()).unwrap();
    assert_eq!(m.num_samples, 100_000);
    assert!(m.chamfer_l1 < 1e-12 && m.chamfer_l2 < 1e-24, "{m:?}");
    assert_eq!((m.precision, m.recall, m.fscore), (1.0, 1.0, 1.0));
    assert!(m.normal_consistency > 1.0 - 1e-9, "{m:?}");
    let iou = volumetric_iou(&a, &a, 20_000, 3).unwrap();
    assert_eq!(iou.iou, Some(1.0));
}

#[test]
fn concentric_spheres_match_closed_forms() {
    // Fine icospheres of radius 1 and s: every distance is close to s − 1 (faces sit within
    // 1.2e-3 of the unit sphere at 5 subdivisions).
    let a = icosphere(5);
    let s = 1.02;
    let b = common::scaled(&a, s);
    let m = surface_metrics(&a, &b, &SurfaceOptions { num_samples: 50_000, ..Default::default() }).unwrap();
    assert!((m.chamfer_l1 - (s - 1.0)).abs() < 2e-3, "{m:?}");
    assert!((m.chamfer_l2 - (s - 1.0f64).powi(2)).abs() < 1e-4, "{m:?}");
    assert!(m.normal_consistency > 0.999, "{m:?}");
    // τ = 0.3% of the diagonal (2√3 ≈ 3.46) ≈ 0.0104 < 0.02: nothing matches.
    assert!((m.fscore_tau - 0.003 * a.diagonal()).abs() < 1e-15);
    assert_eq!(m.fscore, 0.0);
    // With τ = 1% of the diagonal (0.035) everything matches.
    let m = surface_metrics(&a, &b, &SurfaceOptions { num_samples: 50_000, fscore_tau_rel: 0.01, seed: 5 }).unwrap();
    assert_eq!(m.fscore, 1.0);
    // IoU of concentric balls: 1/s³ (volumes of the polyhedra scale exactly by s³).
    let iou = volumetric_iou(&a, &b, 200_000, 7).unwrap();
    let want = 1.0 / (s * s * s);
    assert!((iou.iou.unwrap() - want).abs() < 0.01, "{iou:?} vs {want}");
}

#[test]
fn flipped_normals_still_count_as_consistent() {
    let a = icosphere(3);
    let flipped =
        TriMesh { positions: a.positions.clone(), triangles: a.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect() };
    let m = surface_metrics(&a, &flipped, &SurfaceOptions { num_samples: 10_000, ..Default::default() }).unwrap();
    assert!(m.normal_consistency > 1.0 - 1e-9);
}

#[test]
fn sampling_is_seeded_and_thread_independent() {
    let a = icosphere(3);
    let b = common::translated(&torus(0.8, 0.3, 24, 12), [0.1, 0.0, 0.0]);
    let opts = SurfaceOptions { num_samples: 30_000, seed: 9, ..Default::default() };
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let r1 = one.install(|| surface_metrics(&a, &b, &opts).unwrap());
    assert_eq!(r1, surface_metrics(&a, &b, &opts).unwrap());
    let other = surface_metrics(&a, &b, &SurfaceOptions { seed: 10, ..opts.clone() }).unwrap();
    assert_ne!(r1.chamfer_l1, other.chamfer_l1);
    let i1 = one.install(|| volumetric_iou(&a, &b, 30_000, 1).unwrap());
    assert_eq!(i1, volumetric_iou(&a, &b, 30_000, 1).unwrap());
}

#[test]
fn validity_reports_topology_and_self_intersections() {
    let v = validity(&icosphere(3));
    assert!(v.is_valid_solid && v.is_closed && v.is_manifold && !v.self_intersecting, "{v:?}");
    assert_eq!((v.num_components, v.genus), (1, Some(0)));
    let v = validity(&box_with_hole(1.0, 0.3));
    assert!(v.is_valid_solid, "{v:?}");
    assert_eq!(v.genus, Some(1));
    // Two overlapping spheres: closed and manifold, but they intersect.
    let a = icosphere(2);
    let b = common::translated(&a, [0.5, 0.0, 0.0]);
    let n = a.positions.len() as u32;
    let both = TriMesh {
        positions: a.positions.iter().chain(&b.positions).copied().collect(),
        triangles: a.triangles.iter().copied().chain(b.triangles.iter().map(|t| t.map(|v| v + n))).collect(),
    };
    let v = validity(&both);
    assert!(v.is_closed && v.is_manifold && v.self_intersecting && !v.is_valid_solid, "{v:?}");
    assert_eq!(v.num_components, 2);
    assert!(v.first_self_intersection.is_some());
    // An open mesh.
    let mut open = icosphere(2);
    open.triangles.pop();
    let v = validity(&open);
    assert!(!v.is_closed && !v.is_valid_solid && v.genus.is_none());
}

#[test]
fn evaluate_reports_everything() {
    let reference = icosphere(4);
    let prediction = common::scaled(&icosphere(2), 1.01);
    let opts = EvalOptions {
        surface: SurfaceOptions { num_samples: 20_000, ..Default::default() },
        iou_samples: Some(20_000),
        ..Default::default()
    };
    let r = evaluate(&reference, &prediction, &opts).unwrap();
    assert_eq!(r.format_version, 1);
    let h = &r.hausdorff;
    assert!(h.converged && h.lo <= h.hi && h.hi - h.lo <= 1e-6 * h.diagonal);
    assert_eq!(h.libigl, Some(r.hausdorff_libigl));
    assert!(h.witness >= r.hausdorff_libigl, "{} < {}", h.witness, r.hausdorff_libigl);
    assert!(r.surface.max_prediction_to_reference <= h.hi && r.surface.max_reference_to_prediction <= h.hi);
    assert!(r.iou.as_ref().unwrap().iou.unwrap() > 0.9);
    assert!(r.prediction_validity.as_ref().unwrap().is_valid_solid);
    let json = serde_json::to_value(&r).unwrap();
    // A sphere has no interior faces: every sample is a boundary sample.
    assert_eq!(r.solid_boundary.interior_share, 0.0);
    assert!(r.solid_boundary.hausdorff_estimate <= h.hi);
    for key in [
        "hausdorff_libigl",
        "hausdorff",
        "surface",
        "iou",
        "prediction_validity",
        "solid_boundary",
        "reference_diagonal",
    ] {
        assert!(json.get(key).is_some(), "{key} missing in {json}");
    }
    // Skips.
    let r =
        evaluate(&reference, &prediction, &EvalOptions { iou_samples: Some(0), skip_validity: true, ..opts }).unwrap();
    assert!(r.iou.is_none() && r.prediction_validity.is_none());
}

/// `a` and `b` as one mesh (no welding).
fn union_of(a: &TriMesh, b: &TriMesh) -> TriMesh {
    let n = a.positions.len() as u32;
    TriMesh {
        positions: a.positions.iter().chain(&b.positions).copied().collect(),
        triangles: a.triangles.iter().copied().chain(b.triangles.iter().map(|t| t.map(|v| v + n))).collect(),
    }
}

#[test]
fn interior_faces_are_told_apart_from_the_solid_boundary() {
    // A unit box with a second box [0.4, 0.6]³ inside it (faces inside the solid, as in a CAD
    // union). The box alone is the solid's exact boundary: the certified distance is the
    // inner box's depth, 0.4 (its face centres, e.g. (0.5, 0.5, 0.4)), while nothing on the
    // boundary is away from the prediction.
    let outer = mesh_io::shapes::cuboid([0.0; 3], [1.0; 3]);
    let inner = mesh_io::shapes::cuboid([0.4; 3], [0.6; 3]);
    let reference = union_of(&outer, &inner);
    let opts =
        EvalOptions { surface: SurfaceOptions { num_samples: 40_000, ..Default::default() }, ..Default::default() };
    let r = evaluate(&reference, &outer, &opts).unwrap();
    assert!((r.hausdorff.hi - 0.4).abs() < 1e-5 && (r.hausdorff.lo - 0.4).abs() < 1e-5, "{:?}", r.hausdorff);
    let b = &r.solid_boundary;
    // Area share of the inner box: 0.24 / 6.24, within three binomial standard deviations.
    let want: f64 = 0.24 / 6.24;
    let sd = (want * (1.0 - want) / 40_000.0).sqrt();
    assert!((b.interior_share - want).abs() < 3.0 * sd, "{b:?}");
    assert!(b.max_boundary_to_prediction < 1e-12, "{b:?}");
    assert!(b.max_interior_to_prediction > 0.39 && b.max_interior_to_prediction <= 0.4 + 1e-12, "{b:?}");
    assert!(b.hausdorff_estimate < 1e-12, "{b:?}");
    // A prediction 0.05 too large on every side: the boundary is 0.05 away (up to 0.05·√3
    // at corners that are not sampled exactly), the inner box 0.45.
    let grown = mesh_io::shapes::cuboid([-0.05; 3], [1.05; 3]);
    let r = evaluate(&reference, &grown, &opts).unwrap();
    let b = &r.solid_boundary;
    assert!(b.max_boundary_to_prediction >= 0.05 - 1e-12 && b.max_boundary_to_prediction < 0.05 * 3f64.sqrt());
    assert!(b.max_interior_to_prediction > 0.44 && b.max_interior_to_prediction <= 0.45 + 1e-12, "{b:?}");
    // The other direction (crust corners to the reference) is certified: 0.05·√3.
    assert!((b.hausdorff_estimate - 0.05 * 3f64.sqrt()).abs() < 1e-5, "{b:?}");
    // An open sheet has outside on both sides: all boundary, none interior.
    let sheet = TriMesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    let r = evaluate(&sheet, &outer, &EvalOptions { iou_samples: Some(0), ..opts }).unwrap();
    assert_eq!(r.solid_boundary.interior_share, 0.0);
}

#[test]
fn bad_inputs_are_errors() {
    let good = icosphere(1);
    // Zero area: every triangle degenerate. Hausdorff works, sampling cannot.
    let flat = TriMesh { positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], triangles: vec![[0, 1, 2]] };
    let e = surface_metrics(&good, &flat, &SurfaceOptions::default()).unwrap_err();
    assert!(matches!(e, MetricsError::ZeroArea { mesh: "prediction", .. }), "{e}");
    assert!(e.to_string().contains("positive, finite area"));
    assert!(matches!(evaluate(&good, &flat, &EvalOptions::default()), Err(MetricsError::ZeroArea { .. })));
    let e = evaluate(&TriMesh::default(), &good, &EvalOptions::default()).unwrap_err();
    assert!(matches!(e, MetricsError::Empty { mesh: "reference" }), "{e}");
    let nan = TriMesh { positions: vec![[0.0, f64::NAN, 0.0]; 3], triangles: vec![[0, 1, 2]] };
    assert!(matches!(
        evaluate(&good, &nan, &EvalOptions::default()),
        Err(MetricsError::BadVertex { mesh: "prediction", .. })
    ));
    assert!(matches!(volumetric_iou(&good, &nan, 10, 0), Err(MetricsError::BadVertex { .. })));
    assert!(matches!(volumetric_iou(&good, &good, 0, 0), Err(MetricsError::BadOption(_))));
    for bad in [
        SurfaceOptions { num_samples: 0, ..Default::default() },
        SurfaceOptions { fscore_tau_rel: -1.0, ..Default::default() },
        SurfaceOptions { fscore_tau_rel: f64::INFINITY, ..Default::default() },
    ] {
        assert!(matches!(surface_metrics(&good, &good, &bad), Err(MetricsError::BadOption(_))));
    }
    // validity never fails, even on an empty mesh.
    assert!(!validity(&TriMesh::default()).is_valid_solid);
}
