//! glTF's JOINTS_0/WEIGHTS_0 carry at most four influences per vertex; body models carry up to
//! all joints. Keeping the four largest and renormalising is what every exporter does, and loses
//! little because skinning weights are concentrated near a few bones.

/// The (up to) four largest positive weights of one vertex's row with their joint indices, the
/// weights renormalised to sum to one. Unused slots are joint 0 with weight 0, as the validator
/// expects. `None` when the row has no positive weight.
pub fn top_four(row: &[f32]) -> Option<([u16; 4], [f32; 4])> {
    let mut best: Vec<(usize, f32)> = row.iter().copied().enumerate().filter(|&(_, w)| w > 0.0).collect();
    // Largest first; ties keep the lower joint index first so the choice is deterministic.
    best.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    best.truncate(4);
    let sum: f64 = best.iter().map(|&(_, w)| w as f64).sum();
    if best.is_empty() || sum <= 0.0 {
        return None;
    }
    let mut joints = [0u16; 4];
    let mut weights = [0f32; 4];
    for (slot, &(j, w)) in best.iter().enumerate() {
        joints[slot] = j as u16;
        weights[slot] = (w as f64 / sum) as f32;
    }
    Some((joints, weights))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_four_largest_and_renormalises() {
        let row = [0.05, 0.3, 0.0, 0.1, 0.2, 0.35];
        let (j, w) = top_four(&row).unwrap();
        assert_eq!(j, [5, 1, 4, 3]);
        let kept = 0.35 + 0.3 + 0.2 + 0.1;
        for (got, want) in w.iter().zip([0.35 / kept, 0.3 / kept, 0.2 / kept, 0.1 / kept]) {
            assert!((got - want).abs() < 1e-7);
        }
    }

    #[test]
    fn pads_with_zero_weights_and_rejects_empty_rows() {
        assert_eq!(top_four(&[0.0, 2.0, 0.0]), Some(([1, 0, 0, 0], [1.0, 0.0, 0.0, 0.0])));
        assert_eq!(top_four(&[0.0, 0.0]), None);
    }
}
