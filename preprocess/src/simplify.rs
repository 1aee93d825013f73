//! Stage 6½, simplify: the skeleton graph without the features narrower than a size in
//! metres, so that the partition is a property of the level and not of the voxel size.
//!
//! A finer grid resolves gaps a coarser one closes: at 512 voxels Crytek Sponza's empty space
//! has 395 independent cycles (64 at 256, 41 at 128) — cracks between roof tiles, gaps under
//! railings and between ornaments a few centimetres wide — and every one of them gives the
//! skeleton a loop with junctions, the segmentation its topology and coverage nodes and the
//! greedy growth a chain of small clusters. Light passes through such gaps (the portals still
//! carry it: every voxel keeps a cluster), but they should not shape the partition.
//!
//! 1. **Thin cycles are opened.** Every independent cycle of the graph is opened at its
//!    narrowest edge (an edge weighs the smaller max ball of its two nodes) when that edge is
//!    narrower than `min_gap_m`: the edges outside a maximum spanning forest are each the
//!    narrowest of their cycle, and those below the size are dropped. Cycles through wide
//!    openings (an arcade, a ring of rooms) stay.
//! 2. **Thin branches are pruned.** An end whose max ball is below `min_gap_m`, and every end
//!    an opened cycle left, is removed, and so on along its line until a junction, a node
//!    wider than `PEEL_LIMIT` times the size, or the last node of its component: what is left
//!    of an opened cycle goes back to the rooms it joined.
//!
//! A removed node is attached to the node through which it was removed, followed to a node
//! that stays: the segmentation gives it that node's segmented node, so its voxels go to the
//! cluster of the space they open onto. The stored skeleton and the topology check keep the
//! whole graph.

/// An opened cycle's ends are pruned while their max ball stays below this many times the
/// size: a wide room is never pruned, only the gap and the narrow line leading to it.
/// [Units: ratio]
pub const PEEL_LIMIT: f32 = 2.0;

/// The simplified graph.
#[derive(Debug, Clone, PartialEq)]
pub struct Simplified {
    /// Sorted adjacency lists; a removed node has none.
    pub adjacency: Vec<Vec<u32>>,
    /// For every node, the node that stands for it: itself when kept, a kept node of its
    /// component when removed.
    pub attach: Vec<u32>,
    /// Edges dropped to open thin cycles.
    pub cycles_opened: u64,
    /// Nodes removed.
    pub nodes_removed: u64,
}

impl Simplified {
    /// Whether node `n` was removed.
    pub fn removed(&self, n: usize) -> bool {
        self.attach[n] as usize != n
    }
}

/// Simplifies the graph given by sorted adjacency lists and each node's max-ball radius (see
/// the module notes); `min_gap_m` ≤ 0 keeps the graph as it is.
pub fn simplify(adjacency: &[Vec<u32>], radius: &[f32], min_gap_m: f32) -> Simplified {
    let n = adjacency.len();
    let mut adj: Vec<Vec<u32>> = adjacency.to_vec();
    let mut attach: Vec<u32> = (0..n as u32).collect();
    if min_gap_m <= 0.0 {
        return Simplified {
            adjacency: adj,
            attach,
            cycles_opened: 0,
            nodes_removed: 0,
        };
    }
    let (dropped, mut opened) = open_thin_cycles(adjacency, radius, min_gap_m);
    for &[a, b] in &dropped {
        adj[a as usize].retain(|&x| x != b);
        adj[b as usize].retain(|&x| x != a);
    }
    // Peel ends: thin ones, and those of opened cycles while they stay below the limit.
    let mut stack: Vec<u32> = (0..n as u32)
        .filter(|&i| adj[i as usize].len() == 1)
        .collect();
    stack.reverse();
    let mut removed = 0u64;
    while let Some(i) = stack.pop() {
        let iu = i as usize;
        if adj[iu].len() != 1 {
            continue;
        }
        let r = radius[iu];
        if !(r < min_gap_m || (opened[iu] && r < PEEL_LIMIT * min_gap_m)) {
            continue;
        }
        let j = adj[iu][0];
        adj[iu].clear();
        adj[j as usize].retain(|&x| x != i);
        attach[iu] = j;
        removed += 1;
        if opened[iu] {
            opened[j as usize] = true;
        }
        if adj[j as usize].len() == 1 {
            stack.push(j);
        }
    }
    // Follow each removed node to a kept one (attachments point to nodes removed later or
    // kept, so the chains end).
    for i in 0..n {
        let mut k = i;
        while attach[k] as usize != k {
            k = attach[k] as usize;
        }
        attach[i] = k as u32;
    }
    Simplified {
        adjacency: adj,
        attach,
        cycles_opened: dropped.len() as u64,
        nodes_removed: removed,
    }
}

/// The edges to drop (outside a maximum spanning forest by edge width, narrower than
/// `min_gap_m`) and which nodes they leave as ends of an opened cycle.
fn open_thin_cycles(
    adjacency: &[Vec<u32>],
    radius: &[f32],
    min_gap_m: f32,
) -> (Vec<[u32; 2]>, Vec<bool>) {
    let n = adjacency.len();
    let mut edges: Vec<(f32, [u32; 2])> = adjacency
        .iter()
        .enumerate()
        .flat_map(|(a, l)| {
            l.iter()
                .filter(move |&&b| (b as usize) > a)
                .map(move |&b| (radius[a].min(radius[b as usize]), [a as u32, b]))
        })
        .collect();
    // Widest first; ties in index order, so the result does not depend on anything else.
    edges.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    let mut parent: Vec<u32> = (0..n as u32).collect();
    let find = |parent: &mut Vec<u32>, mut x: u32| {
        while parent[x as usize] != x {
            let p = parent[parent[x as usize] as usize];
            parent[x as usize] = p;
            x = p;
        }
        x
    };
    let mut dropped = Vec::new();
    let mut opened = vec![false; n];
    for (w, [a, b]) in edges {
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[ra as usize] = rb;
        } else if w < min_gap_m {
            dropped.push([a, b]);
            opened[a as usize] = true;
            opened[b as usize] = true;
        }
    }
    (dropped, opened)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sorted adjacency lists of `n` nodes and the given edges.
    fn graph(n: usize, edges: &[[u32; 2]]) -> Vec<Vec<u32>> {
        let mut adj = vec![Vec::new(); n];
        for &[a, b] in edges {
            adj[a as usize].push(b);
            adj[b as usize].push(a);
        }
        adj.iter_mut().for_each(|l| l.sort_unstable());
        adj
    }

    /// A ring of `n` nodes.
    fn ring(n: u32) -> Vec<[u32; 2]> {
        (0..n).map(|i| [i, (i + 1) % n]).collect()
    }

    #[test]
    fn a_wide_ring_stays_and_a_ring_through_a_crack_opens_and_goes_back_to_the_room() {
        // A ring of 12 wide nodes (1 m).
        let adj = graph(12, &ring(12));
        let s = simplify(&adj, &[1.0; 12], 0.15);
        assert_eq!(s.cycles_opened, 0);
        assert_eq!(s.nodes_removed, 0);
        assert_eq!(s.adjacency, adj);
        // A room (nodes 0–5, 1 m) and a crack (6–11, 0.05 m) closing the loop.
        let mut r = [1.0f32; 12];
        r[6..].fill(0.05);
        let s = simplify(&adj, &r, 0.15);
        assert_eq!(s.cycles_opened, 1);
        assert_eq!(s.nodes_removed, 6, "the whole crack goes");
        for i in 0..6 {
            assert!(!s.removed(i));
            assert_eq!(s.attach[i], i as u32);
        }
        for i in 6..12 {
            assert!(s.removed(i));
            assert!(s.attach[i] == 0 || s.attach[i] == 5, "{:?}", s.attach);
        }
        // The room is a line now, its ends where the crack was.
        assert_eq!(s.adjacency[0], vec![1]);
        assert_eq!(s.adjacency[5], vec![4]);
    }

    #[test]
    fn thin_spurs_go_wide_spurs_stay_and_a_thin_component_keeps_a_node() {
        // A line 0–1–2–3 (wide) with a thin spur 2–4–5 and a wide spur 1–6–7.
        let adj = graph(8, &[[0, 1], [1, 2], [2, 3], [2, 4], [4, 5], [1, 6], [6, 7]]);
        let mut r = [1.0f32; 8];
        r[4] = 0.1;
        r[5] = 0.05;
        let s = simplify(&adj, &r, 0.15);
        assert_eq!(s.nodes_removed, 2);
        assert_eq!((s.attach[4], s.attach[5]), (2, 2));
        assert_eq!(s.adjacency[2], vec![1, 3]);
        assert_eq!(s.adjacency[6], vec![1, 7]);
        // A thin component alone shrinks to one node.
        let adj = graph(3, &[[0, 1], [1, 2]]);
        let s = simplify(&adj, &[0.05; 3], 0.15);
        assert_eq!(s.nodes_removed, 2);
        let kept: Vec<usize> = (0..3).filter(|&i| !s.removed(i)).collect();
        assert_eq!(kept.len(), 1);
        assert!(s.attach.iter().all(|&a| a as usize == kept[0]));
        // Size 0 keeps everything.
        let s = simplify(&adj, &[0.05; 3], 0.0);
        assert_eq!((s.nodes_removed, s.cycles_opened), (0, 0));
    }

    #[test]
    fn an_opened_cycle_stops_at_wide_nodes() {
        // Two rooms (0–3 and 6–9, 1 m) joined by a door line 3–4–5–6 (0.5 m) and by a crack
        // 0–10–9 (0.05 m): the crack goes, the door line and the rooms stay.
        let mut e: Vec<[u32; 2]> = (0..9).map(|i| [i, i + 1]).collect();
        e.extend([[0, 10], [10, 9]]);
        let adj = graph(11, &e);
        let mut r = [1.0f32; 11];
        r[4] = 0.5;
        r[5] = 0.5;
        r[10] = 0.05;
        let s = simplify(&adj, &r, 0.15);
        assert_eq!(s.cycles_opened, 1);
        assert_eq!(s.nodes_removed, 1);
        assert!(s.removed(10));
        assert!((0..10).all(|i| !s.removed(i)));
    }
}
