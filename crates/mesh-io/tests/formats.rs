//! Reading every format, writing every format, and reading back.

use std::path::{Path, PathBuf};

use mesh_io::{
    read_mesh, shapes, write_gltf, write_mesh, ErrorKind, GltfLayout, Location, SceneMesh, TopologyReport, TriMesh,
};

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn triangle_set(m: &TriMesh) -> Vec<[[u64; 3]; 3]> {
    m.canonical_triangles()
}

/// When the test runner sets VF_GLB_OUT, keep a copy of a written glTF/GLB (and its .bin)
/// there: tests/reference/test_mesh_io.py runs the Khronos validator on every one.
fn keep_for_validation(path: &Path, tag: &str) {
    let Some(dir) = std::env::var_os("VF_GLB_OUT") else { return };
    let dir = PathBuf::from(dir);
    std::fs::create_dir_all(&dir).unwrap();
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    std::fs::copy(path, dir.join(format!("{tag}_{name}"))).unwrap();
    let bin = path.with_extension("bin");
    if name.ends_with(".gltf") && bin.exists() {
        // The .gltf names its .bin: keep the pair in a folder of its own.
        let sub = dir.join(tag);
        std::fs::create_dir_all(&sub).unwrap();
        std::fs::copy(path, sub.join(&name)).unwrap();
        std::fs::copy(&bin, sub.join(bin.file_name().unwrap())).unwrap();
        std::fs::remove_file(dir.join(format!("{tag}_{name}"))).unwrap();
    }
}

fn f32_rounded(m: &TriMesh) -> TriMesh {
    TriMesh {
        positions: m.positions.iter().map(|p| p.map(|c| c as f32 as f64)).collect(),
        triangles: m.triangles.clone(),
    }
}

#[test]
fn obj_quads_are_fan_triangulated_and_welded() {
    let d = tmp();
    let p = write(d.path(), "q.obj", b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 0\nf 1 2 3 4\nf 5 4 3\n");
    let m = read_mesh(&p).unwrap();
    assert_eq!(m.positions.len(), 4, "the duplicate vertex 5 is welded onto vertex 1");
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 2]]);
}

#[test]
fn obj_negative_indices_and_missing_mtl() {
    let d = tmp();
    let p = write(d.path(), "n.obj", b"mtllib missing.mtl\nusemtl x\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n");
    assert_eq!(read_mesh(&p).unwrap().triangles, vec![[0, 1, 2]]);
}

/// A backslash at the end of a line continues it (the OBJ format; trimesh's `wallhole.obj`
/// splits long faces so, with CRLF endings). Lines after a joined one keep their numbers in
/// errors, and a comment ending in a backslash does not swallow the next line. A `usemtl`
/// without a name (the same file) does not matter: materials are not read.
#[test]
fn obj_lines_continued_by_a_backslash_are_joined() {
    let d = tmp();
    let quad = b"mtllib 00.mtl\r\nusemtl \r\nv 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\n# C:\\models\\\r\nv 0 1 0\r\nf 1 2 \\\r\n3 4\r\n";
    let p = write(d.path(), "c.obj", quad);
    assert_eq!(read_mesh(&p).unwrap().triangles, vec![[0, 1, 2], [0, 2, 3]]);
    let p = write(d.path(), "lf.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 \\\n 2 \\\n 3\n");
    assert_eq!(read_mesh(&p).unwrap().triangles, vec![[0, 1, 2]]);
    // Line 6 refers to a vertex that does not exist: the joined lines 4–5 do not shift it.
    let p = write(d.path(), "bad.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n3\nf 1 2 9\n");
    let e = read_mesh(&p).unwrap_err();
    assert_eq!((e.kind, &e.location), (ErrorKind::IndexOutOfRange, &Location::Line(6)), "{e}");
}

#[test]
fn every_writer_round_trips_an_icosphere() {
    let d = tmp();
    let m = shapes::icosphere(2);
    for ext in ["obj", "ply", "glb", "gltf"] {
        let p = d.path().join(format!("s.{ext}"));
        write_mesh(&p, &m).unwrap();
        if ext.starts_with("gl") {
            keep_for_validation(&p, "icosphere");
        }
        let back = read_mesh(&p).unwrap();
        let want = if ext.starts_with("gl") { f32_rounded(&m) } else { m.clone() };
        assert_eq!(triangle_set(&back), triangle_set(&want), "{ext}");
        assert_eq!(back.positions.len(), m.positions.len(), "{ext}");
    }
    // Only the outputs, no temporary files, remain.
    let mut names: Vec<String> =
        std::fs::read_dir(d.path()).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    assert_eq!(names, ["s.bin", "s.glb", "s.gltf", "s.obj", "s.ply"]);
}

fn stl_binary(m: &TriMesh) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(m.triangles.len() as u32).to_le_bytes());
    for t in &m.triangles {
        b.extend_from_slice(&[0u8; 12]);
        for &i in t {
            for c in m.positions[i as usize] {
                b.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

fn stl_ascii(m: &TriMesh) -> String {
    let mut s = String::from("solid test\n");
    for t in &m.triangles {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for &i in t {
            let p = m.positions[i as usize];
            s += &format!("      vertex {:?} {:?} {:?}\n", p[0], p[1], p[2]);
        }
        s += "    endloop\n  endfacet\n";
    }
    s + "endsolid test\n"
}

#[test]
fn stl_binary_and_ascii_weld_back_to_the_mesh() {
    let d = tmp();
    let m = f32_rounded(&shapes::torus(1.0, 0.3, 16, 8));
    let mut bin = stl_binary(&m);
    bin[..5].copy_from_slice(b"solid"); // many exporters start binary headers with "solid"
    for (name, bytes) in [("b.stl", bin), ("a.stl", stl_ascii(&m).into_bytes())] {
        let back = read_mesh(&write(d.path(), name, &bytes)).unwrap();
        assert_eq!(back.positions.len(), m.positions.len(), "{name}");
        assert_eq!(triangle_set(&back), triangle_set(&m), "{name}");
        let r = TopologyReport::of(&back);
        assert!(r.is_closed && r.is_manifold && r.is_orientation_consistent, "{name}");
        assert_eq!(r.genus, Some(1));
    }
}

fn ply(m: &TriMesh, format: &str) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat {format} 1.0\ncomment test\nelement vertex {}\nproperty float x\nproperty double y\nproperty float z\nproperty uchar red\nelement face {}\nproperty list uchar int vertex_indices\nproperty short flags\nend_header\n",
        m.positions.len(),
        m.triangles.len()
    )
    .into_bytes();
    let big = format.ends_with("big_endian");
    let put = |b: &mut Vec<u8>, mut bytes: Vec<u8>| {
        if big {
            bytes.reverse();
        }
        b.extend_from_slice(&bytes);
    };
    for p in &m.positions {
        if format == "ascii" {
            b.extend_from_slice(format!("{:?} {:?} {:?} 7\n", p[0] as f32 as f64, p[1], p[2] as f32 as f64).as_bytes());
        } else {
            put(&mut b, (p[0] as f32).to_le_bytes().to_vec());
            put(&mut b, p[1].to_le_bytes().to_vec());
            put(&mut b, (p[2] as f32).to_le_bytes().to_vec());
            b.push(7);
        }
    }
    for t in &m.triangles {
        if format == "ascii" {
            b.extend_from_slice(format!("3 {} {} {} -1\n", t[0], t[1], t[2]).as_bytes());
        } else {
            b.push(3);
            for &i in t {
                put(&mut b, (i as i32).to_le_bytes().to_vec());
            }
            put(&mut b, (-1i16).to_le_bytes().to_vec());
        }
    }
    b
}

#[test]
fn ply_ascii_little_and_big_endian_agree() {
    let d = tmp();
    let m = shapes::icosphere(1);
    let want = TriMesh {
        positions: m.positions.iter().map(|p| [p[0] as f32 as f64, p[1], p[2] as f32 as f64]).collect(),
        triangles: m.triangles.clone(),
    };
    for f in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let back = read_mesh(&write(d.path(), &format!("{f}.ply"), &ply(&m, f))).unwrap();
        assert_eq!(back, want, "{f}");
    }
}

#[test]
fn off_with_comments_polygons_and_colours() {
    let d = tmp();
    let p = write(
        d.path(),
        "a.off",
        b"OFF\n# a square and a triangle\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n4 0 1 2 3 255 0 0\n3 0 1 4\n",
    );
    assert_eq!(read_mesh(&p).unwrap().triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
    let p = write(d.path(), "b.off", b"OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    assert_eq!(read_mesh(&p).unwrap().triangles.len(), 1);
}

#[test]
fn gltf_scene_with_several_nodes_and_colours_reads_back() {
    let d = tmp();
    let a = shapes::icosphere(1);
    let b = shapes::box_with_hole(1.0, 0.25);
    let colors = vec![[0.2f32, 0.4, 0.6]; b.positions.len()];
    let p = d.path().join("scene.glb");
    write_gltf(
        &p,
        &[
            SceneMesh { name: "a", mesh: &a, colors: None, normals: Default::default() },
            SceneMesh { name: "empty", mesh: &TriMesh::default(), colors: None, normals: Default::default() },
            SceneMesh { name: "b", mesh: &b, colors: Some(&colors), normals: Default::default() },
        ],
        GltfLayout::Binary,
    )
    .unwrap();
    keep_for_validation(&p, "scene_with_colours");
    let back = read_mesh(&p).unwrap();
    assert_eq!(back.triangles.len(), a.triangles.len() + b.triangles.len());
    let r = TopologyReport::of(&back);
    assert_eq!(r.num_components, 2);
    assert!(r.is_closed);
}

/// POSITION, NORMAL (if any) and indices of a GLB's first primitive.
type GlbArrays = (Vec<[f32; 3]>, Option<Vec<[f32; 3]>>, Vec<u32>);

/// The first primitive's POSITION and NORMAL (if any) of a GLB, and its indices.
fn glb_arrays(path: &Path) -> GlbArrays {
    let g = gltf::Gltf::open(path).unwrap();
    let blob = g.blob.as_deref().unwrap();
    let read = |a: gltf::Accessor| -> Vec<u8> {
        let v = a.view().unwrap();
        let at = v.offset() + a.offset();
        let size = a.size() * a.count();
        blob[at..at + size].to_vec()
    };
    let f32s = |b: Vec<u8>| -> Vec<[f32; 3]> {
        b.chunks_exact(12)
            .map(|c| [0, 1, 2].map(|k| f32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap())))
            .collect()
    };
    let prim = g.meshes().next().unwrap().primitives().next().unwrap();
    let pos = f32s(read(prim.get(&gltf::Semantic::Positions).unwrap()));
    let nor = prim.get(&gltf::Semantic::Normals).map(|a| f32s(read(a)));
    let idx =
        read(prim.indices().unwrap()).chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect();
    (pos, nor, idx)
}

/// The normals a GLB carries: none by default (viewers shade flat; every vertex shared),
/// one per vertex with `Smooth`, and with `Crease` a copy of a vertex per side of each
/// sharp edge (a cube's corner three times, each with its face's normal) but none on a
/// smooth shape, whose normals are then the smooth ones. Every file reads back as the same
/// closed mesh (the reader welds by position) and goes to the Khronos validator.
#[test]
fn glb_normals_flat_smooth_and_creased() {
    use mesh_io::{write_mesh_with, Normals};
    let d = tmp();
    let cube = shapes::cuboid([0.0; 3], [1.0, 2.0, 3.0]);
    let sphere = shapes::icosphere(3);
    for (name, mesh) in [("cube", &cube), ("sphere", &sphere)] {
        for normals in [Normals::Flat, Normals::Smooth, Normals::Crease(40.0)] {
            let p = d.path().join(format!("{name}_{}.glb", normals.to_string().replace(':', "_")));
            write_mesh_with(&p, mesh, normals).unwrap();
            keep_for_validation(&p, "normals");
            let back = read_mesh(&p).unwrap();
            assert!(back.canonical_triangles() == f32_rounded(mesh).canonical_triangles(), "{name} {normals}");
            let (pos, nor, idx) = glb_arrays(&p);
            assert_eq!(idx.len(), 3 * mesh.triangles.len());
            match (normals, name) {
                (Normals::Flat, _) => assert!(nor.is_none() && pos.len() == mesh.positions.len()),
                (Normals::Smooth, _) => assert_eq!(nor.unwrap(), mesh_io::vertex_normals(mesh)),
                (Normals::Crease(_), "cube") => {
                    assert_eq!(pos.len(), 24, "each of 8 corners once per face");
                    let nor = nor.unwrap();
                    for t in idx.chunks_exact(3) {
                        let [a, b, c] = [0, 1, 2].map(|k| pos[t[k] as usize].map(f64::from));
                        let e = [[b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]];
                        let n = [
                            e[0][1] * e[1][2] - e[0][2] * e[1][1],
                            e[0][2] * e[1][0] - e[0][0] * e[1][2],
                            e[0][0] * e[1][1] - e[0][1] * e[1][0],
                        ];
                        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                        for &i in t {
                            let dot: f64 = (0..3).map(|k| f64::from(nor[i as usize][k]) * n[k] / len).sum();
                            assert!(dot > 1.0 - 1e-6, "a cube's corner takes its face's normal ({dot})");
                        }
                    }
                }
                (Normals::Crease(_), _) => {
                    assert_eq!(pos.len(), mesh.positions.len(), "no crease on an icosphere");
                    assert_eq!(nor.unwrap(), mesh_io::vertex_normals(mesh));
                }
            }
        }
    }
    assert_eq!(Normals::parse("crease").unwrap(), Normals::Crease(mesh_io::DEFAULT_CREASE_DEGREES));
    assert_eq!(Normals::parse("crease:30").unwrap(), Normals::Crease(30.0));
    assert_eq!(Normals::parse("flat").unwrap(), Normals::default());
    for bad in ["crease:0", "crease:180", "crease:x", "round", ""] {
        assert!(Normals::parse(bad).is_err(), "{bad}");
    }
}

/// A glTF written by hand: a node with a mirroring scale (negative determinant) under a
/// translated parent, and a triangle strip. The reader applies the transforms in f64 and
/// flips the winding under the mirror.
#[test]
fn gltf_node_transforms_and_strips() {
    use base64::Engine as _;
    let d = tmp();
    let mut bin = Vec::new();
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]] {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 3] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin));
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"translation":[10,0,0],"children":[1]}},{{"scale":[-1,1,1],"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"mode":5}}]}}],
        "buffers":[{{"byteLength":{},"uri":"{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":8}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5123,"count":4,"type":"SCALAR"}}]}}"#,
        bin.len()
    );
    let m = read_mesh(&write(d.path(), "t.gltf", json.as_bytes())).unwrap();
    assert_eq!(m.positions, vec![[10.0, 0.0, 0.0], [9.0, 0.0, 0.0], [10.0, 1.0, 0.0], [9.0, 1.0, 0.0]]);
    // Strip (0,1,2), (2,1,3) — then flipped by the mirror: (0,2,1), (2,3,1).
    assert_eq!(m.triangles, vec![[0, 2, 1], [2, 3, 1]]);
}

#[test]
fn errors_name_the_line_or_element() {
    let d = tmp();
    let cases: &[(&str, &[u8], ErrorKind, Location)] = &[
        ("nan.obj", b"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", ErrorKind::NonFinite, Location::Line(3)),
        ("idx.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n", ErrorKind::IndexOutOfRange, Location::Line(5)),
        ("garbage.obj", b"hello world\nthis is not a mesh\n", ErrorKind::Empty, Location::File),
        ("empty.ply", b"", ErrorKind::Empty, Location::File),
        ("two.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", ErrorKind::Syntax, Location::Line(6)),
        ("inf.off", b"OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n", ErrorKind::NonFinite, Location::Line(4)),
        ("loop.stl", b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n", ErrorKind::Truncated, Location::Line(3)),
        ("big.ply", b"ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n", ErrorKind::Truncated, Location::File),
        ("face.ply", b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", ErrorKind::IndexOutOfRange, Location::Line(13)),
        ("x.xyz", b"1 2 3\n", ErrorKind::UnknownFormat, Location::File),
    ];
    for (name, bytes, kind, loc) in cases {
        let p = write(d.path(), name, bytes);
        let e = read_mesh(&p).unwrap_err();
        assert_eq!((e.kind, &e.location), (*kind, loc), "{name}: {e}");
        let msg = e.to_string();
        assert!(msg.starts_with(&p.display().to_string()), "{name}: {msg}");
    }
}

#[test]
fn a_failed_write_leaves_nothing_behind() {
    let d = tmp();
    let p = d.path().join("out.obj");
    std::fs::write(&p, b"old").unwrap();
    let e = mesh_io::atomic_write(&p, |w| {
        w.write_all(b"partial")?;
        Err(std::io::Error::other("simulated disk full"))
    })
    .unwrap_err();
    assert_eq!(e.kind, ErrorKind::Write);
    assert_eq!(std::fs::read(&p).unwrap(), b"old", "the old file is untouched");
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 1, "no temporary file remains");
    let missing_dir = d.path().join("no/such/dir/out.glb");
    assert_eq!(write_mesh(&missing_dir, &shapes::icosphere(0)).unwrap_err().kind, ErrorKind::Write);
}

/// Regression: a GLB header declaring a total length below 12 bytes made gltf 1.4 panic
/// on an integer underflow.
#[test]
fn glb_with_tiny_declared_length_is_an_error_not_a_panic() {
    let d = tmp();
    let mut b = b"glTF".to_vec();
    b.extend_from_slice(&2u32.to_le_bytes());
    b.extend_from_slice(&4u32.to_le_bytes());
    b.extend_from_slice(&[0u8; 20]);
    let e = read_mesh(&write(d.path(), "tiny.glb", &b)).unwrap_err();
    assert_eq!((e.kind, e.location), (ErrorKind::Syntax, Location::Byte(8)));
}

/// A 2 × 2 grid of unit squares in the plane z = 0 as triangle strips: one strip per row
/// of squares, the rows separated by -1, and a zero-area joint (a repeated vertex) inside
/// the second strip that must not become a face.
fn tristrip_ply(format: &str) -> Vec<u8> {
    let v = |r: i32, c: i32| r * 3 + c;
    let strips: Vec<i32> = vec![
        v(0, 0),
        v(1, 0),
        v(0, 1),
        v(1, 1),
        v(0, 2),
        v(1, 2),
        -1,
        v(1, 0),
        v(2, 0),
        v(1, 1),
        v(2, 1),
        v(1, 2),
        v(2, 2),
        v(2, 2),
    ];
    let mut b = format!(
        "ply\nformat {format} 1.0\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n"
    )
    .into_bytes();
    for r in 0..3 {
        for c in 0..3 {
            if format == "ascii" {
                b.extend_from_slice(format!("{c} {r} 0\n").as_bytes());
            } else {
                for x in [c as f32, r as f32, 0.0] {
                    b.extend_from_slice(&x.to_le_bytes());
                }
            }
        }
    }
    if format == "ascii" {
        let ids: Vec<String> = strips.iter().map(|i| i.to_string()).collect();
        b.extend_from_slice(format!("{} {}\n", strips.len(), ids.join(" ")).as_bytes());
    } else {
        b.extend_from_slice(&(strips.len() as i32).to_le_bytes());
        for i in &strips {
            b.extend_from_slice(&i.to_le_bytes());
        }
    }
    b
}

#[test]
fn ply_triangle_strips_become_consistently_oriented_triangles() {
    let d = tmp();
    for f in ["ascii", "binary_little_endian"] {
        let m = read_mesh(&write(d.path(), &format!("strips_{f}.ply"), &tristrip_ply(f))).unwrap();
        assert_eq!(m.triangles.len(), 8, "{f}: {:?}", m.triangles);
        let mut area = 0.0;
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            // z of (b - a) × (c - a): every triangle of the strip faces the same way
            let z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            assert!(z < 0.0, "{f}: triangle {t:?} is flipped against the first");
            area -= z / 2.0;
        }
        assert_eq!(area, 4.0, "{f}");
        let r = TopologyReport::of(&m);
        assert!(r.is_manifold && r.is_orientation_consistent && r.num_boundary_loops == 1, "{f}: {r:?}");
    }
    // a vertex id past the end is named with the element
    let bad = String::from_utf8(tristrip_ply("ascii")).unwrap().replace("\n14 0 3", "\n14 0 9");
    let e = read_mesh(&write(d.path(), "bad_strip.ply", bad.as_bytes())).unwrap_err();
    assert_eq!(e.kind, ErrorKind::IndexOutOfRange, "{e}");
    assert!(e.to_string().contains("tristrips 0 refers to vertex 9"), "{e}");
}
