//! Edge strain: how much each edge is longer or shorter than at rest, |l/l₀ − 1|.

/// The largest and the mean edge strain of the mesh `faces` between `rest` and `current`
/// positions. Edges with an index out of range or of zero rest length are left out; with no edge
/// left both are 0.
pub fn edge_strain(rest: &[[f32; 3]], current: &[[f32; 3]], faces: &[[u32; 3]]) -> (f32, f32) {
    let edges = mannequin_mesh::adjacency::edges(faces);
    let strains: Vec<f64> = edges
        .iter()
        .filter_map(|&e| {
            let (l0, l) = (edge_length(rest, e)?, edge_length(current, e)?);
            (l0 > 0.0).then(|| (l / l0 - 1.0).abs())
        })
        .collect();
    if strains.is_empty() {
        return (0.0, 0.0);
    }
    let max = strains.iter().copied().fold(0.0, f64::max);
    (max as f32, (strains.iter().sum::<f64>() / strains.len() as f64) as f32)
}

/// The length of edge (a, b) at `p`, in double precision; `None` for an index out of range.
fn edge_length(p: &[[f32; 3]], [a, b]: [u32; 2]) -> Option<f64> {
    let (a, b) = (p.get(a as usize)?, p.get(b as usize)?);
    Some((0..3).map(|k| (a[k] as f64 - b[k] as f64).powi(2)).sum::<f64>().sqrt())
}

/// The `q` quantile (0–1) of the edges' stretch max(l/l₀ − 1, 0): how far the most stretched
/// edges are past their rest length, ignoring compression (cloth buckles rather than resists it).
pub fn stretch_quantile(rest: &[[f32; 3]], current: &[[f32; 3]], faces: &[[u32; 3]], q: f64) -> f32 {
    let mut stretch: Vec<f64> = mannequin_mesh::adjacency::edges(faces)
        .iter()
        .filter_map(|&e| {
            let (l0, l) = (edge_length(rest, e)?, edge_length(current, e)?);
            (l0 > 0.0).then(|| (l / l0 - 1.0).max(0.0))
        })
        .collect();
    if stretch.is_empty() {
        return 0.0;
    }
    stretch.sort_by(f64::total_cmp);
    let at = ((q.clamp(0.0, 1.0) * (stretch.len() - 1) as f64).round()) as usize;
    stretch[at] as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_stretched_along_x() {
        let rest = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let stretched = [[0.0, 0.0, 0.0], [1.5, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let (max, mean) = edge_strain(&rest, &stretched, &[[0, 1, 2]]);
        let hypotenuse = (1.5f32.hypot(1.0) / 2f32.sqrt()) - 1.0;
        assert!((max - 0.5).abs() < 1e-6);
        assert!((mean - (0.5 + hypotenuse) / 3.0).abs() < 1e-6);
        // Stretches sorted: 0 (the unchanged leg), the hypotenuse's, 0.5.
        assert_eq!(stretch_quantile(&rest, &stretched, &[[0, 1, 2]], 0.0), 0.0);
        assert!((stretch_quantile(&rest, &stretched, &[[0, 1, 2]], 0.5) - hypotenuse).abs() < 1e-6);
        assert!((stretch_quantile(&rest, &stretched, &[[0, 1, 2]], 1.0) - 0.5).abs() < 1e-6);
        // Compression is not stretch.
        let squeezed = [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(stretch_quantile(&rest, &squeezed, &[[0, 1, 2]], 1.0), 0.0);
    }
}
