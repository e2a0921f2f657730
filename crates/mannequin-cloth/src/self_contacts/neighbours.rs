//! Each particle's neighbours along edges, to tell contacts within one small patch of cloth, where
//! no side can be told apart, from contacts between layers.

#[derive(Debug, Clone, Default)]
pub(crate) struct Neighbours {
    /// `list[starts[v]..starts[v + 1]]`: the neighbours of v, sorted.
    starts: Vec<u32>,
    list: Vec<u32>,
}

impl Neighbours {
    pub fn new(edges: &[[u32; 2]], vertex_count: usize) -> Self {
        let mut starts = vec![0u32; vertex_count + 1];
        for &[a, b] in edges {
            starts[a as usize + 1] += 1;
            starts[b as usize + 1] += 1;
        }
        for v in 0..vertex_count {
            starts[v + 1] += starts[v];
        }
        let mut next = starts.clone();
        let mut list = vec![0u32; 2 * edges.len()];
        for &[a, b] in edges {
            for (from, to) in [(a, b), (b, a)] {
                list[next[from as usize] as usize] = to;
                next[from as usize] += 1;
            }
        }
        for v in 0..vertex_count {
            list[starts[v] as usize..starts[v + 1] as usize].sort_unstable();
        }
        Self { starts, list }
    }

    /// Whether some particle of `a` is a neighbour of some particle of `b`.
    pub fn touch(&self, a: &[u32], b: &[u32]) -> bool {
        a.iter().any(|&v| {
            let ring = &self.list[self.starts[v as usize] as usize..self.starts[v as usize + 1] as usize];
            b.iter().any(|w| ring.binary_search(w).is_ok())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_along_a_path() {
        let n = Neighbours::new(&[[0, 1], [1, 2], [2, 3]], 4);
        assert!(n.touch(&[0], &[1]) && n.touch(&[3, 0], &[2]));
        assert!(!n.touch(&[0], &[2, 3]));
    }
}
