//! Greedy graph colouring of constraints: constraints of one colour share no particle, so each
//! colour can be projected by many threads at once, and the result does not depend on how the
//! colour was split between them (a Gauss–Seidel sweep colour by colour, parallel within each).

use std::ops::Range;

/// Constraints reordered so that each colour is one contiguous range.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Colouring {
    /// `order[k]` is the original index of the constraint that goes to slot k.
    pub order: Vec<usize>,
    pub colours: Vec<Range<usize>>,
}

/// Gives each constraint the smallest colour that none of its particles has yet, in index order.
pub(crate) fn greedy_colouring<const N: usize>(constraints: &[[u32; N]], vertex_count: usize) -> Colouring {
    let mut vertex_colours: Vec<Vec<u32>> = vec![Vec::new(); vertex_count];
    let mut taken: Vec<bool> = Vec::new();
    let mut colour_of = Vec::with_capacity(constraints.len());
    for particles in constraints {
        for &v in particles {
            for &c in &vertex_colours[v as usize] {
                taken[c as usize] = true;
            }
        }
        let colour = taken.iter().position(|&t| !t).unwrap_or(taken.len());
        if colour == taken.len() {
            taken.push(false);
        }
        taken.fill(false);
        for &v in particles {
            vertex_colours[v as usize].push(colour as u32);
        }
        colour_of.push(colour);
    }
    let mut counts = vec![0usize; taken.len()];
    for &c in &colour_of {
        counts[c] += 1;
    }
    let mut colours = Vec::with_capacity(counts.len());
    let mut start = 0;
    for &n in &counts {
        colours.push(start..start + n);
        start += n;
    }
    let mut next: Vec<usize> = colours.iter().map(|r| r.start).collect();
    let mut order = vec![0; constraints.len()];
    for (i, &c) in colour_of.iter().enumerate() {
        order[next[c]] = i;
        next[c] += 1;
    }
    Colouring { order, colours }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checks the colouring's promise directly: within a colour, no particle appears twice.
    fn assert_independent<const N: usize>(
        constraints: &[[u32; N]],
        colouring: &Colouring,
        vertex_count: usize,
    ) {
        let mut sorted = colouring.order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..constraints.len()).collect::<Vec<_>>(), "every constraint once");
        for range in &colouring.colours {
            let mut seen = vec![false; vertex_count];
            for &k in &colouring.order[range.clone()] {
                for &v in &constraints[k] {
                    assert!(!seen[v as usize], "particle {v} twice in one colour");
                    seen[v as usize] = true;
                }
            }
        }
    }

    #[test]
    fn a_path_needs_two_colours() {
        let edges: Vec<[u32; 2]> = (0..9).map(|i| [i, i + 1]).collect();
        let c = greedy_colouring(&edges, 10);
        assert_eq!(c.colours.len(), 2);
        assert_independent(&edges, &c, 10);
    }

    #[test]
    fn a_star_needs_one_colour_per_spoke() {
        let edges: Vec<[u32; 2]> = (1..8).map(|i| [0, i]).collect();
        let c = greedy_colouring(&edges, 8);
        assert_eq!(c.colours.len(), 7);
        assert_independent(&edges, &c, 8);
    }

    #[test]
    fn groups_of_four_stay_independent() {
        let quads: Vec<[u32; 4]> =
            (0..50u32).map(|i| [i, (i * 7 + 1) % 60, (i * 13 + 2) % 60, (i * 3 + 5) % 60]).collect();
        let quads: Vec<[u32; 4]> =
            quads.into_iter().filter(|q| (0..4).all(|a| (a + 1..4).all(|b| q[a] != q[b]))).collect();
        let c = greedy_colouring(&quads, 60);
        assert_independent(&quads, &c, 60);
    }
}
