//! The ground-truth rasterizer on scenes whose images are known in closed form.

use glam::DVec3;
use mannequin_data::{Camera, Image};
use mannequin_mesh::UvLayout;
use mannequin_raster::{NO_FACE, RasterMesh, Shading, rasterize, sample_bilinear};

fn camera(w: usize, h: usize) -> Camera {
    // Slightly off-centre principal point and unequal focal lengths, to catch axis mix-ups.
    Camera::new(
        w,
        h,
        [[90.0, 0.0, 33.3], [0.0, 80.0, 27.1], [0.0, 0.0, 1.0]],
        [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]],
    )
}

/// Where the ray through pixel centre (x, y) meets the plane through `o` spanned by `a`, `b`:
/// the parameters (s, t) and the depth, by Cramer's rule.
fn ray_plane(cam: &Camera, x: usize, y: usize, o: DVec3, a: DVec3, b: DVec3) -> (f64, f64, f64) {
    let d = cam.unproject(x as f64 + 0.5, y as f64 + 0.5);
    // o + s a + t b = λ d
    let m = glam::DMat3::from_cols(a, b, -d);
    let sol = m.inverse() * (-o);
    (sol.x, sol.y, sol.z * d.z)
}

#[test]
fn tilted_textured_quad_gives_the_expected_pixels() {
    let cam = camera(64, 56);
    // A parallelogram o + s a + t b, tilted in depth, so perspective correction matters.
    let o = DVec3::new(-0.5, 0.3, 2.0);
    let a = DVec3::new(1.0, 0.0, 0.8);
    let b = DVec3::new(0.1, -0.7, 0.3);
    let corners = [o, o + a, o + a + b, o + b].map(|p| p.as_vec3().to_array());
    let faces = [[0, 1, 2], [0, 2, 3]];
    let uv = UvLayout { coords: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], faces: faces.to_vec() };
    // A texture that is linear in (u, v): red = u and green = v at texel centres.
    let (tw, th) = (16usize, 8usize);
    let texture = Image {
        width: tw,
        height: th,
        pixels: (0..tw * th)
            .map(|p| {
                let (i, j) = (p % tw, p / tw);
                [(i as f32 + 0.5) / tw as f32, 1.0 - (j as f32 + 0.5) / th as f32, 0.25]
            })
            .collect(),
    };
    let normal = a.cross(b).normalize().as_vec3().to_array();
    let mesh = RasterMesh {
        positions: &corners,
        faces: &faces,
        normals: &[normal; 4],
        shading: Shading::Texture { uv: &uv, texture: &texture },
    };
    let out = rasterize(&mesh, &cam, [0.0, 0.0, 1.0]);
    let mut covered = 0;
    for y in 0..cam.height {
        for x in 0..cam.width {
            let (s, t, z) = ray_plane(&cam, x, y, o, a, b);
            let i = y * cam.width + x;
            // Stay a hair away from the border, where coverage is a tie.
            let inside = [s, t].iter().all(|v| (1e-9..1.0 - 1e-9).contains(v));
            let outside = [s, t].iter().any(|v| !(-1e-9..=1.0 + 1e-9).contains(v));
            if outside {
                assert_eq!(out.face_id[i], NO_FACE, "pixel {x},{y}");
                assert_eq!(out.color.pixels[i], [0.0, 0.0, 1.0]);
                continue;
            }
            if !inside {
                continue;
            }
            covered += 1;
            let clamp = |v: f64, n: usize| v.clamp(0.5 / n as f64, 1.0 - 0.5 / n as f64) as f32;
            let c = out.color.pixels[i];
            assert!((c[0] - clamp(s, tw)).abs() < 2e-5, "u at {x},{y}: {} vs {s}", c[0]);
            assert!((c[1] - clamp(t, th)).abs() < 2e-5, "v at {x},{y}: {} vs {t}", c[1]);
            assert!((c[2] - 0.25).abs() < 1e-6);
            assert!(((out.depth.depth[i] as f64) - z).abs() < 1e-5 * z, "depth at {x},{y}");
            assert!(out.mask.values[i]);
        }
    }
    assert!(covered > 500, "{covered}");
}

#[test]
fn fronto_parallel_quad_covers_exactly_the_projected_rectangle() {
    let cam = camera(40, 30);
    // Corners chosen so that the projected edges fall between pixel centres.
    let z = 3.0f32;
    let (u0, u1, v0, v1) = (10.2f32, 27.7f32, 5.4f32, 19.9f32);
    let back = |u: f32, v: f32| [(u - 33.3) / 90.0 * z, (v - 27.1) / 80.0 * z, z];
    let pos = [back(u0, v0), back(u1, v0), back(u1, v1), back(u0, v1)];
    let faces = [[0, 1, 2], [0, 2, 3]];
    let mesh = RasterMesh {
        positions: &pos,
        faces: &faces,
        normals: &[[0.0, 0.0, -1.0]; 4],
        shading: Shading::Flat([1.0; 3]),
    };
    let out = rasterize(&mesh, &cam, [0.0; 3]);
    for y in 0..cam.height {
        for x in 0..cam.width {
            let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
            let want = cx > u0 && cx < u1 && cy > v0 && cy < v1;
            assert_eq!(out.mask.at(x, y), want, "pixel {x},{y}");
        }
    }
    // Pixel centres 10.5..27.5 (18 columns) by 5.5..19.5 (15 rows).
    assert_eq!(out.mask.count(), 18 * 15);
}

/// A UV sphere: positions, faces, and the exact (radial) vertex normals.
struct Sphere {
    positions: Vec<[f32; 3]>,
    faces: Vec<[u32; 3]>,
    normals: Vec<[f32; 3]>,
}

fn uv_sphere(centre: [f32; 3], r: f32, rings: usize, segments: usize) -> Sphere {
    let (positions, faces) = mannequin_mesh::uv_ellipsoid(centre, [r; 3], rings, segments);
    let normals = positions.iter().map(|p| std::array::from_fn(|k| (p[k] - centre[k]) / r)).collect();
    Sphere { positions, faces, normals }
}

#[test]
fn sphere_normal_map_matches_analytic_normals() {
    let cam = Camera::look_at([0.4, 0.3, -3.0], [0.1, -0.1, 0.2], [0.0, 1.0, 0.0], 0.6, 96, 80);
    let (c, r) = (DVec3::new(0.1, -0.1, 0.2), 0.5);
    let sphere = uv_sphere(c.as_vec3().to_array(), r as f32, 96, 192);
    let mesh = RasterMesh {
        positions: &sphere.positions,
        faces: &sphere.faces,
        normals: &sphere.normals,
        shading: Shading::Flat([1.0; 3]),
    };
    let out = rasterize(&mesh, &cam, [0.0; 3]);
    let (rot, eye) = (cam.rotation(), DVec3::from(cam.centre()));
    let (mut checked, mut worst) = (0, 0.0f64);
    for y in 0..cam.height {
        for x in 0..cam.width {
            // Analytic ray-sphere hit in world space.
            let d = (rot.transpose() * cam.unproject(x as f64 + 0.5, y as f64 + 0.5)).normalize();
            let oc = eye - c;
            let (bq, cq) = (oc.dot(d), oc.length_squared() - r * r);
            let disc = bq * bq - cq;
            let i = y * cam.width + x;
            if disc < 0.0 {
                // Misses the true sphere, so it misses the inscribed mesh too.
                assert!(!out.mask.values[i], "pixel {x},{y}");
                continue;
            }
            let hit = eye + d * (-bq - disc.sqrt());
            let n_world = (hit - c) / r;
            // Skip grazing pixels, where the tessellated silhouette differs from the sphere.
            if n_world.dot(-d) < 0.2 {
                continue;
            }
            assert!(out.mask.values[i], "pixel {x},{y}");
            let n_cam = rot * n_world;
            let got = DVec3::from(out.normals.normals[i].map(f64::from));
            worst = worst.max(got.dot(n_cam).clamp(-1.0, 1.0).acos().to_degrees());
            // Depth along z: within the sagitta of a facet of this tessellation.
            let z = (rot * (hit - eye)).z;
            assert!((out.depth.depth[i] as f64 - z).abs() < 2e-3, "depth at {x},{y}");
            checked += 1;
        }
    }
    assert!(checked > 1500, "{checked}");
    assert!(worst < 0.5, "worst normal error {worst}°");
}

#[test]
fn nearer_surface_wins_and_plane_depth_is_exact() {
    let cam = camera(48, 40);
    // Two planes crossing: z = 2 + 0.5 x and the fronto-parallel z = 2.2.
    let quad = |z: &dyn Fn(f32, f32) -> f32| {
        [(-2.0, -2.0), (2.0, -2.0), (2.0, 2.0), (-2.0, 2.0)].map(|(x, y)| [x, y, z(x, y)])
    };
    let mut pos = quad(&|x, _| 2.0 + 0.5 * x).to_vec();
    pos.extend(quad(&|_, _| 2.2));
    let faces = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
    let mesh = RasterMesh {
        positions: &pos,
        faces: &faces,
        normals: &[[0.0, 0.0, -1.0]; 8],
        shading: Shading::Flat([1.0; 3]),
    };
    let out = rasterize(&mesh, &cam, [0.0; 3]);
    for y in 0..cam.height {
        for x in 0..cam.width {
            let d = cam.unproject(x as f64 + 0.5, y as f64 + 0.5);
            // On z = 2 + 0.5 x with x = d.x z: z = 2 / (1 - 0.5 d.x).
            let z_tilted = 2.0 / (1.0 - 0.5 * d.x);
            let want = z_tilted.min(2.2);
            let i = y * cam.width + x;
            assert!((out.depth.depth[i] as f64 - want).abs() < 1e-5, "pixel {x},{y}");
            if (z_tilted - 2.2).abs() > 1e-6 {
                let face = out.face_id[i];
                assert_eq!(face < 2, z_tilted < 2.2, "pixel {x},{y}");
            }
        }
    }
}

#[test]
fn bilinear_sampling_interpolates_between_texel_centres() {
    let tex = Image {
        width: 2,
        height: 2,
        pixels: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };
    // Top-left texel centre is (u, v) = (0.25, 0.75).
    assert_eq!(sample_bilinear(&tex, glam::Vec2::new(0.25, 0.75)), [0.0; 3]);
    assert_eq!(sample_bilinear(&tex, glam::Vec2::new(0.75, 0.25)), [0.0, 0.0, 1.0]);
    let mid = sample_bilinear(&tex, glam::Vec2::new(0.5, 0.5));
    assert_eq!(mid, [0.25, 0.25, 0.25]);
    // Clamped outside.
    assert_eq!(sample_bilinear(&tex, glam::Vec2::new(-1.0, 2.0)), [0.0; 3]);
}

/// Vertex colours on the tilted quad: red = s and green = t at the corners (s, t) of
/// o + s a + t b, so each pixel's colour is where its ray meets the plane, in closed form.
#[test]
fn vertex_colours_interpolate_perspective_correctly() {
    let cam = camera(64, 56);
    let o = DVec3::new(-0.5, 0.3, 2.0);
    let a = DVec3::new(1.0, 0.0, 0.8);
    let b = DVec3::new(0.1, -0.7, 0.3);
    let corners = [o, o + a, o + a + b, o + b].map(|p| p.as_vec3().to_array());
    let colours = [[0.0, 0.0, 0.5], [1.0, 0.0, 0.5], [1.0, 1.0, 0.5], [0.0, 1.0, 0.5]];
    let faces = [[0, 1, 2], [0, 2, 3]];
    let normal = a.cross(b).normalize().as_vec3().to_array();
    let mesh = RasterMesh {
        positions: &corners,
        faces: &faces,
        normals: &[normal; 4],
        shading: Shading::Vertex(&colours),
    };
    let out = rasterize(&mesh, &cam, [0.0; 3]);
    let mut covered = 0;
    for y in 0..cam.height {
        for x in 0..cam.width {
            if out.face_id[y * cam.width + x] == NO_FACE {
                continue;
            }
            covered += 1;
            let (s, t, _) = ray_plane(&cam, x, y, o, a, b);
            let got = out.color.at(x, y);
            assert!(
                (got[0] - s as f32).abs() < 1e-4 && (got[1] - t as f32).abs() < 1e-4,
                "({x}, {y}): {got:?} vs ({s}, {t})"
            );
            assert!((got[2] - 0.5).abs() < 1e-6);
        }
    }
    assert!(covered > 300, "{covered} pixels covered");
}
