//! Every category made on the default body: a clean open manifold with the category's openings,
//! near-uniform triangles at the asked edge length, standing off the body by its ease (down to
//! the seat, for those draped below it), and carried to the template's own body unchanged
//! (Eq. 3.2 at β = β^g).

use glam::Vec3;
use mannequin_body::smpl_joint::PELVIS;
use mannequin_body::{BodyModel, shape_body};
use mannequin_cloth::quality::{self_intersecting_pairs, vertices_inside_body};
use mannequin_garment::region::Landmarks;
use mannequin_garment::{Category, Dressed, Ease, Garment, make_garment};
use mannequin_mesh::adjacency::{boundary_loops, edges};
use mannequin_mesh::{ClosestPoint, TriMesh};

/// Each edge in at most two faces, and each vertex's faces one fan (no bow-ties).
fn assert_manifold(name: &str, mesh: &TriMesh) {
    let mut count = std::collections::HashMap::new();
    for t in &mesh.faces {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    assert!(count.values().all(|&n| n <= 2), "{name}: an edge in more than two faces");
    // A bow-tie vertex sits on two boundary loops, or twice on one.
    let mut seen = std::collections::HashSet::new();
    for l in boundary_loops(&mesh.faces) {
        for v in l {
            assert!(seen.insert(v), "{name}: vertex {v} is on the boundary twice (a bow-tie)");
        }
    }
}

/// Pants XL among them: eased out along the body's normals their inner legs crossed each other
/// between the thighs (25 pairs), and a crossed template cannot be simulated with its contacts.
#[test]
fn every_close_fitting_category_is_a_clean_eased_manifold_that_transfers_to_its_own_body() {
    let model = BodyModel::default_body();
    let body = model.template_mesh();
    for (category, openings, size) in [
        (Category::Pants, 3, "M"),
        (Category::Pants, 3, "XL"),
        (Category::ShortPants, 3, "XL"),
        (Category::Tshirt, 4, "XL"),
        (Category::Shirt, 4, "S"),
    ] {
        let g = check_template(category, openings, size, f32::NEG_INFINITY);
        let name = format!("{} {size}", category.name());
        let inside = vertices_inside_body(&g.mesh.positions, &body.positions, &body.faces);
        assert_eq!(inside, 0, "{name}: {inside} vertices inside the body");
        let crossing = self_intersecting_pairs(&g.mesh.positions, &g.mesh.faces);
        assert_eq!(crossing, 0, "{name}: {crossing} pairs of its triangles cross");
    }
}

/// The skirt (waist, hem), the dress (neck, arms, hem) and the coat (one opening from the
/// neck down the front round the hem, and the cuffs): sewn panels draped below the seat, never
/// inside the body nor through themselves, their hems where the fit puts them.
#[test]
fn every_draped_category_is_a_clean_manifold_clear_of_the_body() {
    let model = BodyModel::default_body();
    let body = model.template_mesh();
    let joints = shape_body(&model, &[]).unwrap().joints;
    let floor = body.positions.iter().map(|p| p[1]).fold(f32::INFINITY, f32::min);
    for (category, openings, size) in
        [(Category::Skirt, 2, "M"), (Category::Dress, 4, "S"), (Category::LongCoat, 3, "L")]
    {
        let name = category.name();
        let g = check_template(category, openings, size, joints[PELVIS].y);
        let inside = vertices_inside_body(&g.mesh.positions, &body.positions, &body.faces);
        assert_eq!(inside, 0, "{name}: {inside} vertices inside the body");
        let crossing = self_intersecting_pairs(&g.mesh.positions, &g.mesh.faces);
        assert_eq!(crossing, 0, "{name}: {crossing} pairs of its triangles cross");
        let lowest = g.mesh.positions.iter().map(|p| p[1]).fold(f32::INFINITY, f32::min) - floor;
        let hem = Landmarks::new(&body.positions, &joints).default_hem_height(category);
        assert!((lowest - hem).abs() < 0.05, "{name}: hem {lowest} m above the floor, asked {hem}");
    }
}

/// Makes `category` at `size` and checks it: manifold with `openings` boundary loops, no
/// slivers, edges near the target length, standing off the body by the fit's ease above
/// `loose_below` (a rest height), UVs, and Eq. 3.2 on its own body giving it back.
fn check_template(category: Category, openings: usize, size: &str, loose_below: f32) -> Garment {
    let model = BodyModel::default_body();
    let body = model.template_mesh();
    let index = ClosestPoint::new(&body.positions, &body.faces, 0.03);
    let fit = Ease::size(size).unwrap();
    let name = format!("{} {size}", category.name());
    let name = name.as_str();
    let target = 0.015;
    let g = make_garment(category, fit, target, category.default_material(), &model, "default", &[]).unwrap();
    assert_manifold(name, &g.mesh);
    let smallest = mannequin_mesh::double_areas(&g.mesh.positions, &g.mesh.faces)
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    // A third of an equilateral triangle's area at the target length, at least.
    assert!(
        smallest > 0.3 * 3f64.sqrt() / 2.0 * (target as f64).powi(2) / 3.0,
        "{name}: a {smallest} m² sliver"
    );
    let loops: Vec<usize> = boundary_loops(&g.mesh.faces).iter().map(Vec::len).collect();
    assert_eq!(loops.len(), openings, "{name}: openings of {loops:?} vertices");

    let lengths: Vec<f32> = edges(&g.mesh.faces)
        .iter()
        .map(|&[a, b]| {
            Vec3::from(g.mesh.positions[a as usize]).distance(Vec3::from(g.mesh.positions[b as usize]))
        })
        .collect();
    let mean = lengths.iter().sum::<f32>() / lengths.len() as f32;
    let sd = (lengths.iter().map(|l| (l - mean).powi(2)).sum::<f32>() / lengths.len() as f32).sqrt();
    assert!((mean - target).abs() < 0.15 * target, "{name}: mean edge {mean}");
    assert!(sd / mean < 0.3, "{name}: edge CV {}", sd / mean);

    // Every vertex stands off the body by about the ease (between 0.5 and 1.5 × the least
    // and most of the fit's three values), measured against the body mesh directly.
    let (lo, hi) =
        (fit.ease_waist.min(fit.ease_hips).min(fit.ease_chest), fit.ease_chest.max(fit.ease_waist));
    let off = g.mesh.positions.iter().filter(|&&p| p[1] > loose_below).filter(|&&p| {
        let d = index.query(Vec3::from(p)).unwrap().1.distance(Vec3::from(p));
        !(0.5 * lo..=1.5 * hi).contains(&d)
    });
    let off = off.count();
    assert!(
        off * 100 < g.vertex_count(),
        "{name}: {off} of {} vertices off the eased surface",
        g.vertex_count()
    );
    assert!(g.mesh.uv.as_ref().is_some_and(|uv| uv.faces.len() == g.mesh.faces.len()), "{name}: UVs");

    // Eq. 3.2 on the template's own body gives the template back.
    let dressed = Dressed::new(&g, &model, &[]).unwrap();
    let worst = dressed
        .rest()
        .iter()
        .zip(&g.mesh.positions)
        .map(|(a, b)| Vec3::from(*a).distance(Vec3::from(*b)))
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-5, "{name}: {worst} m from the template");
    g
}
