//! Where the face mesh network puts its 468 points on the default head, found by asking it.
//!
//! `tools/default_body/face_landmarks.py` places each landmark by registering MediaPipe's
//! canonical face to the head: a generic correspondence, 5.3 % of the eyes' distance from what
//! the network reads on renders of the head itself. This tool renders the neutral default head
//! with a real face's colours (the `face.obj` that `mannequin face fit` writes for a photo) in 30
//! views (yaw −20…20°, pitch −10…10°, two sizes), reads the landmarks with the shipped face
//! models, casts each point's ray onto the rendered surface, and takes per landmark the median
//! of its rest-head positions over the views where its surface faces the camera. That median,
//! moved to the nearest point of the head's surface, is the landmark's new triangle and
//! barycentrics. Landmarks seen in fewer than 5 views keep their registered place.
//!
//! ```text
//! cargo run --release -p mannequin -- face fit --image crates/mannequin-fit/tests/data/astronaut.png --out /tmp/astronaut
//! cargo run --release -p mannequin-fit --example calibrate_face_landmarks -- /tmp/astronaut/face.obj crates/mannequin-fit/data/face_landmarks.npz
//! ```

use glam::{DQuat, DVec3, Vec3};
use mannequin_body::{BodyModel, FaceModel};
use mannequin_data::mesh_raster::NO_FACE;
use mannequin_fit::FaceModels;
use mannequin_fit::body_fit::picture_camera;
use mannequin_fit::face_landmark_table::FaceLandmarkTable;
use mannequin_fit::face_render::{LitHead, render_head};
use mannequin_io::{NpyArray, NpzWriter};
use mannequin_mesh::{ClosestPoint, read_obj};

const SIDE: usize = 512;
const MIN_VIEWS: usize = 5;
/// A point counts in a view when its triangle faces the camera at least this much (cosine).
const FACING: f64 = 0.3;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, obj, out] = args.as_slice() else {
        panic!("usage: calibrate_face_landmarks FACE.obj OUT.npz");
    };
    let (body, face) = (BodyModel::default_body(), FaceModel::default_face());
    let colours = read_obj(obj).unwrap().colors.expect("face.obj with vertex colours");
    assert_eq!(
        colours.len(),
        face.vertices.len(),
        "face.obj is the default head (one colour per head vertex)"
    );
    let mut slot = vec![None; body.num_vertices()];
    face.vertices.iter().enumerate().for_each(|(i, &v)| slot[v] = Some(i as u32));
    // The head's triangles in head indices, and each one's triangle of the whole body.
    let (faces, body_face): (Vec<[u32; 3]>, Vec<usize>) = body
        .faces
        .iter()
        .enumerate()
        .filter_map(|(k, f)| Some(([slot[f[0] as usize]?, slot[f[1] as usize]?, slot[f[2] as usize]?], k)))
        .unzip();
    let rest: Vec<DVec3> =
        face.vertices.iter().map(|&v| DVec3::from(body.v_template[v].map(f64::from))).collect();
    let old = FaceLandmarkTable::default_head();
    let old_points = old.positions(&body.v_template, &body.faces).unwrap();
    let centre = old_points.iter().map(|p| DVec3::from(p.map(f64::from))).sum::<DVec3>() / 468.0;

    let models = FaceModels::load().unwrap();
    let camera = picture_camera(SIDE, SIDE, SIDE as f64);
    let mut seen: Vec<Vec<DVec3>> = vec![Vec::new(); 468];
    let mut views = 0;
    for width in [170.0, 280.0] {
        for yaw in [-20.0f64, -10.0, 0.0, 10.0, 20.0] {
            for pitch in [-10.0f64, 0.0, 10.0] {
                let turn = DQuat::from_euler(glam::EulerRot::YXZ, yaw.to_radians(), pitch.to_radians(), 0.0);
                let rotation = DQuat::from_rotation_x(std::f64::consts::PI) * turn;
                let translation = DVec3::new(0.0, 0.0, SIDE as f64 * 0.16 / width);
                let points: Vec<DVec3> =
                    rest.iter().map(|x| rotation * (*x - centre) + translation).collect();
                let light = DVec3::new(-0.3, -0.4, -1.0).normalize();
                let head = LitHead { points: &points, faces: &faces, colours: &colours, light, ambient: 0.5 };
                let (image, raster) = render_head(&head, &camera, [0.5; 3]);
                let Some(found) = models.faces(&image).unwrap().into_iter().next() else {
                    println!("yaw {yaw}°, pitch {pitch}°, width {width}: no face found");
                    continue;
                };
                views += 1;
                for (i, p) in found.landmarks.points.iter().enumerate() {
                    let (x, y) = (p[0].floor() as usize, p[1].floor() as usize);
                    if x >= SIDE || y >= SIDE || raster.face_id[y * SIDE + x] == NO_FACE {
                        continue;
                    }
                    let t = faces[raster.face_id[y * SIDE + x] as usize].map(|v| points[v as usize]);
                    let ray = camera.unproject(p[0] as f64, p[1] as f64).normalize();
                    let normal = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                    if normal.dot(-ray) < FACING {
                        continue;
                    }
                    // Where the ray meets the triangle's plane, in barycentrics.
                    let s = normal.dot(t[0]) / normal.dot(ray);
                    let hit = s * ray;
                    let area = (t[1] - t[0]).cross(t[2] - t[0]).dot(normal);
                    let b = [
                        (t[2] - t[1]).cross(hit - t[1]).dot(normal) / area,
                        (t[0] - t[2]).cross(hit - t[2]).dot(normal) / area,
                        (t[1] - t[0]).cross(hit - t[0]).dot(normal) / area,
                    ];
                    let corners = faces[raster.face_id[y * SIDE + x] as usize].map(|v| rest[v as usize]);
                    seen[i].push(b[0] * corners[0] + b[1] * corners[1] + b[2] * corners[2]);
                }
            }
        }
    }
    println!("{views} views read");

    let head_positions: Vec<[f32; 3]> = rest.iter().map(|p| p.as_vec3().to_array()).collect();
    let closest = ClosestPoint::new(&head_positions, &faces, 0.01);
    let (mut triangles, mut barycentrics, mut moved, mut kept) = (Vec::new(), Vec::new(), Vec::new(), 0);
    for (i, positions) in seen.iter().enumerate() {
        if positions.len() < MIN_VIEWS {
            triangles.push(old.triangles[i] as i64);
            barycentrics.extend(old.barycentrics[i].map(f64::from));
            kept += 1;
            continue;
        }
        let median = |c: usize| {
            let mut v: Vec<f64> = positions.iter().map(|p| p[c]).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let target = Vec3::new(median(0) as f32, median(1) as f32, median(2) as f32);
        let (surface, at) = closest.query(target).expect("the head has faces");
        triangles.push(body_face[surface.face as usize] as i64);
        barycentrics.extend(surface.bary.map(f64::from));
        moved.push(1000.0 * at.distance(Vec3::from(old_points[i])) as f64);
    }
    moved.sort_by(f64::total_cmp);
    println!(
        "{} landmarks placed from the views ({kept} kept their registered place); moved by {:.1} mm (median), {:.1} mm (90 %), {:.1} mm (most)",
        moved.len(),
        moved[moved.len() / 2],
        moved[moved.len() * 9 / 10],
        moved[moved.len() - 1]
    );
    let mut npz = NpzWriter::new();
    npz.add("triangles", NpyArray::i64(vec![468], triangles));
    npz.add("barycentrics", NpyArray::f64(vec![468, 3], barycentrics));
    npz.write(out).unwrap();
    println!("wrote {out}");
}
