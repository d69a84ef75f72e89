//! Animated-mesh readers and writers through the public API: OBJ sequences, PC2, glTF samples.

use crate::common::{base64, media_path};
use mcgv_video::mesh::{read_animation, write_obj_sequence, write_pc2, AnimatedMesh, ReadOptions};
use std::path::{Path, PathBuf};

fn read(input: &str) -> mcgv_video::Result<AnimatedMesh> {
    read_animation(input, &ReadOptions::default())
}

fn error_of(input: &str) -> String {
    match read(input) {
        Ok(m) => panic!("{input} read as {} vertices", m.vertex_count()),
        Err(e) => e.to_string(),
    }
}

/// A quad (two triangles) and a fifth vertex no face uses, moving over `frames` frames.
fn small_animation(frames: usize) -> AnimatedMesh {
    let frames = (0..frames)
        .map(|f| {
            let t = f as f32 * 0.1;
            vec![
                [0.0, 0.0, t],
                [1.0, 0.0, -t],
                [1.0, 1.0, 0.5 * t],
                [0.0, 1.0, 1.0 / 3.0],
                [7.25, -1e-7, t * t],
            ]
        })
        .collect();
    AnimatedMesh::new(vec![[0, 1, 2], [0, 2, 3]], frames).unwrap()
}

fn write(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
}

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

#[test]
fn obj_sequence_round_trip_keeps_everything() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("seq");
    let mesh = small_animation(12);
    write_obj_sequence(&mesh, &out).unwrap();
    assert!(out.join("frame_0000.obj").is_file() && out.join("frame_0011.obj").is_file());
    assert_eq!(read(out.to_str().unwrap()).unwrap(), mesh);
    let glob = format!("{}/*.obj", out.display());
    assert_eq!(read(&glob).unwrap(), mesh);
    let one = read(out.join("frame_0003.obj").to_str().unwrap()).unwrap();
    assert_eq!(one.frame_count(), 1);
    assert_eq!(one.frame(0), mesh.frame(3));
}

#[test]
fn obj_names_grow_past_four_digits_when_needed() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = small_animation(10_001);
    write_obj_sequence(&mesh, dir.path()).unwrap();
    assert!(dir.path().join("frame_00000.obj").is_file());
    assert!(dir.path().join("frame_10000.obj").is_file());
}

#[test]
fn frames_are_ordered_by_the_number_in_the_name() {
    for names in [
        ["frame_1.obj", "frame_2.obj", "frame_10.obj"],
        ["1.obj", "2.obj", "10.obj"],
        ["mesh.01.obj", "mesh.02.obj", "mesh.10.obj"],
    ] {
        let dir = tempfile::tempdir().unwrap();
        for (k, name) in names.iter().enumerate() {
            let text = format!("v {k} 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
            write(&dir.path().join(name), &text);
        }
        let mesh = read(dir.path().to_str().unwrap()).unwrap();
        let xs: Vec<f32> = mesh.frames().iter().map(|f| f[0][0]).collect();
        assert_eq!(xs, [0.0, 1.0, 2.0], "{names:?}");
    }
}

#[test]
fn ragged_sequence_names_the_frame() {
    let dir = tempfile::tempdir().unwrap();
    write(&dir.path().join("f_1.obj"), QUAD);
    write(&dir.path().join("f_2.obj"), QUAD);
    write(
        &dir.path().join("f_3.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n",
    );
    let err = error_of(dir.path().to_str().unwrap());
    assert!(
        err.contains("f_3.obj") && err.contains("3 vertices"),
        "{err}"
    );
}

#[test]
fn changed_connectivity_names_the_frame_and_face() {
    let dir = tempfile::tempdir().unwrap();
    write(&dir.path().join("a_0.obj"), QUAD);
    write(
        &dir.path().join("a_1.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 4\nf 2 3 4\n",
    );
    let err = error_of(dir.path().to_str().unwrap());
    assert!(
        err.contains("a_1.obj") && err.contains("triangle 0"),
        "{err}"
    );
    assert!(err.contains("f 1 2 4") && err.contains("f 1 2 3"), "{err}");

    write(
        &dir.path().join("a_1.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\n",
    );
    let err = error_of(dir.path().to_str().unwrap());
    assert!(
        err.contains("a_1.obj") && err.contains("1 triangles"),
        "{err}"
    );
}

#[test]
fn bad_numbers_empty_files_and_missing_inputs_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let nan = dir.path().join("nan.obj");
    write(&nan, "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
    let err = error_of(nan.to_str().unwrap());
    assert!(
        err.contains("nan.obj") && err.contains("line 2") && err.contains("finite"),
        "{err}"
    );

    let inf = dir.path().join("inf.obj");
    write(&inf, "v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n");
    assert!(error_of(inf.to_str().unwrap()).contains("finite"));

    let empty = dir.path().join("empty.obj");
    write(&empty, "# nothing\n");
    assert!(error_of(empty.to_str().unwrap()).contains("no vertices"));

    let points = dir.path().join("points.obj");
    write(&points, "v 0 0 0\nv 1 0 0\n");
    assert!(error_of(points.to_str().unwrap()).contains("no faces"));

    let none = dir.path().join("nothing");
    std::fs::create_dir(&none).unwrap();
    assert!(error_of(none.to_str().unwrap()).contains("no .obj files"));
    assert!(error_of(&format!("{}/*.obj", none.display())).contains("no .obj files match"));
    let ply = dir.path().join("mesh.ply");
    write(&ply, "ply\n");
    assert!(error_of(ply.to_str().unwrap()).contains("not a form this tool reads"));
    assert!(error_of(dir.path().join("missing.obj").to_str().unwrap()).contains("no such"));
}

/// A huge but finite coordinate (1e30) passed every check and panicked in k-means++ seeding
/// (rand's "Uniform::new: range overflow"); it is refused as the mesh is built, naming the vertex.
#[test]
fn coordinates_beyond_the_limit_are_refused_naming_frame_and_vertex() {
    let square = |z: f32| vec![[0.0, 0.0, z], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let mut far = square(0.0);
    far[2][1] = -1e30;
    let err = AnimatedMesh::new(vec![[0, 1, 2]], vec![square(0.0), far])
        .expect_err("1e30 accepted")
        .to_string();
    assert!(
        err.contains("frame 1, vertex 2") && err.contains("beyond"),
        "{err}"
    );
    let limit = mcgv_video::mesh::MAX_COORDINATE;
    assert!(AnimatedMesh::new(vec![[0, 1, 2]], vec![square(0.0), square(limit)]).is_ok());
}

/// A UTF-8 byte-order mark before the first line glued onto its `v`, and that vertex was
/// silently dropped (then "face refers to vertex 4, but the file has 3"). Later frames are read
/// by their positions alone when alike: with and without the mark, they read the same.
#[test]
fn a_byte_order_mark_before_the_first_line_is_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("plain");
    let marked = dir.path().join("marked");
    for (folder, bom) in [(&plain, ""), (&marked, "\u{feff}")] {
        std::fs::create_dir(folder).unwrap();
        for f in 0..3 {
            // Frame 2 has no mark: a file need not match the first one's.
            let bom = if f == 2 { "" } else { bom };
            let text = format!("{bom}v {f} 0 0\nv 1 0 {f}\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
            write(&folder.join(format!("frame_{f}.obj")), &text);
        }
    }
    let want = read(plain.to_str().unwrap()).unwrap();
    assert_eq!(want.vertex_count(), 4);
    assert_eq!(read(marked.to_str().unwrap()).unwrap(), want);
    let one = mcgv_video::mesh::parse_obj(&format!("\u{feff}{QUAD}"), Path::new("q.obj")).unwrap();
    assert_eq!(one.vertex_count(), 4);
}

/// The reader's triangles, read through positions, must be the ones `tobj` makes of the same file
/// (which renumbers vertices per object, so only positions can be compared).
#[test]
fn triangulation_agrees_with_tobj() {
    let text = "\
v 0 0 0\nv 1 0 0\nv 2 0.5 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nv 0 0 1\nv 1 0 1\nv 1 1 1\n\
o first\nf 1 2 3 4 5\ng second\nf 7/1 8/2 9/3\nf -3//1 -2//1 4//1 1//1\n";
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("poly.obj");
    write(&path, text);
    let ours = read(path.to_str().unwrap()).unwrap();
    assert_eq!(ours.vertex_count(), 9, "the unused vertex 6 is kept");
    let ours: Vec<[[f32; 3]; 3]> = ours
        .triangles()
        .iter()
        .map(|t| t.map(|i| ours.frame(0)[i as usize]))
        .collect();
    let options = tobj::LoadOptions {
        triangulate: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(&path, &options).unwrap();
    let theirs: Vec<[[f32; 3]; 3]> = models
        .iter()
        .flat_map(|m| {
            let p = &m.mesh.positions;
            m.mesh.indices.chunks(3).map(move |t| {
                t.iter()
                    .map(|&i| {
                        [
                            p[3 * i as usize],
                            p[3 * i as usize + 1],
                            p[3 * i as usize + 2],
                        ]
                    })
                    .collect::<Vec<_>>()
                    .try_into()
                    .unwrap()
            })
        })
        .collect();
    assert_eq!(ours, theirs);
}

#[test]
fn pc2_round_trip_with_the_base_beside_it_or_named() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = small_animation(7);
    let pc2 = dir.path().join("anim.pc2");
    write_pc2(&mesh, &pc2).unwrap();
    let base_dir = dir.path().join("base");
    write_obj_sequence(
        &AnimatedMesh::new(mesh.triangles().to_vec(), vec![mesh.frame(3).to_vec()]).unwrap(),
        &base_dir,
    )
    .unwrap();
    let base = base_dir.join("frame_0000.obj");

    let named = ReadOptions {
        base: Some(base.clone()),
        ..Default::default()
    };
    assert_eq!(read_animation(pc2.to_str().unwrap(), &named).unwrap(), mesh);

    let err = error_of(pc2.to_str().unwrap());
    assert!(err.contains("base") && err.contains("anim.obj"), "{err}");
    std::fs::copy(&base, dir.path().join("anim.obj")).unwrap();
    assert_eq!(read(pc2.to_str().unwrap()).unwrap(), mesh);
}

#[test]
fn truncated_or_mismatched_pc2_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = small_animation(3);
    let pc2 = dir.path().join("cut.pc2");
    write_pc2(&mesh, &pc2).unwrap();
    write_obj_sequence(&small_animation(1), dir.path()).unwrap();
    std::fs::rename(
        dir.path().join("frame_0000.obj"),
        dir.path().join("cut.obj"),
    )
    .unwrap();
    let bytes = std::fs::read(&pc2).unwrap();
    std::fs::write(&pc2, &bytes[..bytes.len() - 5]).unwrap();
    let err = error_of(pc2.to_str().unwrap());
    assert!(
        err.contains("cut.pc2") && err.contains("truncated"),
        "{err}"
    );

    std::fs::write(&pc2, &bytes).unwrap();
    write(&dir.path().join("cut.obj"), QUAD);
    let err = error_of(pc2.to_str().unwrap());
    assert!(
        err.contains("5 points") && err.contains("4 vertices") && err.contains("cut.obj"),
        "{err}"
    );
}

#[test]
fn writers_name_the_path_they_fail_on() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("plain");
    write(&file, "x");
    let err = write_obj_sequence(&small_animation(2), &file.join("sub"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("plain"), "{err}");
    let err = write_pc2(&small_animation(2), &file.join("a.pc2"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("a.pc2"), "{err}");
    let leftovers: Vec<PathBuf> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(leftovers, vec![file]);
}

#[test]
fn glb_samples_read_with_their_published_sizes() {
    for (name, vertices, faces) in [
        ("RiggedSimple.glb", 160, 188),
        ("CesiumMan.glb", 3273, 4672),
        ("Fox.glb", 1728, 576),
        ("RiggedFigure.glb", 370, 256),
    ] {
        let mesh = read(&media_path(name)).unwrap();
        assert_eq!(mesh.vertex_count(), vertices, "{name}");
        assert_eq!(mesh.triangles().len(), faces, "{name}");
        assert!(
            mesh.frame_count() > 10,
            "{name}: {} frames",
            mesh.frame_count()
        );
        assert_ne!(
            mesh.frame(0),
            mesh.frame(mesh.frame_count() / 2),
            "{name} does not move"
        );
    }
}

/// The largest distance any vertex moves between two consecutive frames.
fn largest_step(mesh: &AnimatedMesh) -> f32 {
    mesh.frames()
        .windows(2)
        .flat_map(|w| w[0].iter().zip(&w[1]))
        .map(|(a, b)| {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        })
        .fold(0.0, f32::max)
}

/// CesiumMan, skinned: stays a 1.5 m figure in every frame, and its motion is continuous: baked at
/// twice the rate, the largest per-frame step halves (a jump in the motion would not shrink).
#[test]
fn cesium_man_is_human_sized_and_moves_continuously() {
    let mesh = read(&media_path("CesiumMan.glb")).unwrap();
    assert_eq!(mesh.frame_count(), 48, "2 s of 24 keys/s");
    for f in 0..mesh.frame_count() {
        let (lo, hi) = mcgv_video::mesh::bounding_box(mesh.frame(f));
        let height = hi[1] - lo[1];
        assert!((1.3..1.7).contains(&height), "frame {f}: {height} m tall");
    }
    let step = largest_step(&mesh);
    let diagonal = mesh.bbox_diagonal() as f32;
    assert!(step < 0.1 * diagonal, "a vertex jumps {step} in one frame");
    assert!(step > 0.005 * diagonal, "hardly any motion: {step}");
    let opts = ReadOptions {
        fps: Some(48.0),
        ..Default::default()
    };
    let denser = largest_step(&read_animation(&media_path("CesiumMan.glb"), &opts).unwrap());
    assert!(
        (0.4..0.6).contains(&(denser / step)),
        "{denser} at 48 fps, {step} at 24 fps"
    );
}

#[test]
fn a_bake_past_the_positions_limit_is_refused_naming_the_rate_that_fits() {
    let at = |fps: f64, max_positions: u64| {
        let opts = ReadOptions {
            fps: Some(fps),
            max_positions,
            ..Default::default()
        };
        read_animation(&media_path("CesiumMan.glb"), &opts)
    };
    let vertices = at(48.0, u64::MAX).unwrap().vertex_count() as u64;
    // 95 frames at 48 frames/s: at the limit bakes, one position fewer is refused before baking.
    assert_eq!(at(48.0, 95 * vertices).unwrap().frame_count(), 95);
    let limit = 95 * vertices - 1;
    let err = at(48.0, limit).unwrap_err().to_string();
    for needle in [
        "fps: 48 bakes",
        "CesiumMan.glb",
        "to 95 frames",
        &format!("{vertices} vertices"),
        &format!("limit of {limit}"),
        "at most 94 frames fit",
    ] {
        assert!(err.contains(needle), "`{needle}` not in: {err}");
    }
    // The rate it names bakes within the limit.
    let rate: f64 = err
        .split("a rate of ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|r| r.parse().ok())
        .unwrap_or_else(|| panic!("no rate in: {err}"));
    assert!(rate < 48.0, "{err}");
    assert!(at(rate, limit).unwrap().frame_count() <= 94);
}

#[test]
fn frame_rate_and_clip_are_chosen_by_the_options() {
    let at = |fps: Option<f64>, clip: Option<&str>| {
        let opts = ReadOptions {
            fps,
            clip: clip.map(str::to_owned),
            ..Default::default()
        };
        read_animation(&media_path("CesiumMan.glb"), &opts)
    };
    let (slow, fast) = (at(None, None).unwrap(), at(Some(48.0), None).unwrap());
    assert_eq!(fast.frame_count(), 95);
    assert_eq!(fast.frame(0), slow.frame(0));
    for (a, b) in fast.frame(2).iter().zip(slow.frame(1)) {
        assert!((0..3).all(|k| (a[k] - b[k]).abs() < 1e-5), "{a:?} vs {b:?}");
    }
    assert!(at(Some(0.0), None).unwrap_err().to_string().contains("fps"));
    let err = at(Some(1e6), None).unwrap_err().to_string();
    assert!(
        err.contains("CesiumMan.glb") && err.contains("fps") && err.contains("frames/s or lower"),
        "{err}"
    );

    let fox = |clip: &str| {
        let opts = ReadOptions {
            clip: Some(clip.into()),
            ..Default::default()
        };
        read_animation(&media_path("Fox.glb"), &opts)
    };
    assert_eq!(fox("Walk").unwrap().frame_count(), 18);
    assert_eq!(fox("2").unwrap(), fox("Run").unwrap());
    let err = fox("Dance").unwrap_err().to_string();
    assert!(
        err.contains("Dance") && err.contains("Survey") && err.contains("Run"),
        "{err}"
    );
}

#[test]
fn gltf_without_animation_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("still.gltf");
    // One triangle: 3 f32 positions, 36 bytes, embedded as base64.
    let bytes: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{}"}}]}}"#,
        base64(&bytes)
    );
    write(&path, &json);
    let err = error_of(path.to_str().unwrap());
    assert!(
        err.contains("still.gltf") && err.contains("no animation"),
        "{err}"
    );
}

/// Two nodes share one mesh of two primitives that share their vertices (as multi-material meshes
/// do); node 0 is moved by 10 in x and its morph target (vertex 2 up by 1 in z) is weighted 0 → 1
/// over one second. Baked at 4 frames/s: 5 frames of 2 × 3 vertices and 2 × 2 triangles.
#[test]
fn morph_targets_and_shared_vertices_in_gltf() {
    let floats: [f32; 22] = [
        0., 0., 0., 1., 0., 0., 0., 1., 0., // positions
        0., 0., 0., 0., 0., 0., 0., 0., 1., // target 0 displacements
        0., 1., // key times
        0., 1., // weights at the keys
    ];
    let bytes: Vec<u8> = floats.iter().flat_map(|v| v.to_le_bytes()).collect();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],
        "nodes":[{{"mesh":0,"translation":[10,0,0]}},{{"mesh":0}}],
        "meshes":[{{"primitives":[
            {{"attributes":{{"POSITION":0}},"targets":[{{"POSITION":1}}]}},
            {{"attributes":{{"POSITION":0}},"targets":[{{"POSITION":1}}]}}]}}],
        "animations":[{{"channels":[{{"sampler":0,"target":{{"node":0,"path":"weights"}}}}],
            "samplers":[{{"input":2,"output":3,"interpolation":"LINEAR"}}]}}],
        "accessors":[
            {{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
            {{"bufferView":0,"byteOffset":36,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[0,0,1]}},
            {{"bufferView":0,"byteOffset":72,"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[1]}},
            {{"bufferView":0,"byteOffset":80,"componentType":5126,"count":2,"type":"SCALAR"}}],
        "bufferViews":[{{"buffer":0,"byteLength":88}}],
        "buffers":[{{"byteLength":88,"uri":"data:application/octet-stream;base64,{}"}}]}}"#,
        base64(&bytes)
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("morph.gltf");
    write(&path, &json);
    let opts = ReadOptions {
        fps: Some(4.0),
        ..Default::default()
    };
    let mesh = read_animation(path.to_str().unwrap(), &opts).unwrap();
    assert_eq!((mesh.vertex_count(), mesh.frame_count()), (6, 5));
    assert_eq!(
        mesh.triangles(),
        [[0, 1, 2], [0, 1, 2], [3, 4, 5], [3, 4, 5]]
    );
    for f in 0..5 {
        let frame = mesh.frame(f);
        assert_eq!(frame[2], [10.0, 1.0, f as f32 / 4.0], "frame {f}");
        assert_eq!(frame[1], [11.0, 0.0, 0.0]);
        assert_eq!(frame[5], [0.0, 1.0, 0.0], "node 1 has no animated weights");
    }
}
