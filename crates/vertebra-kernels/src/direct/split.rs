//! A tree cut into pieces, so that one ragdoll fills a block's lanes: its
//! limbs and head (subtrees hanging from the trunk by one joint) go side
//! by side in the lanes of blocks of their own shape, and the trunk they
//! hang from in another. A few ragdolls, or one, then fill blocks that
//! would otherwise hold one lane each (`docs/direct.md`, "Lanes").
//!
//! A piece is a [`Topology`] of its own whose root is the joint it was
//! cut at, with its trunk-side body left out as a static one would be
//! (`None`); the trunk keeps a [`super::Child::Port`] where each cut joint was.
//! The arithmetic is the whole tree's, node for node and in the same
//! order (children are taken by their joints' indices in the whole tree),
//! so a tree gives the same bits cut or whole: the choice is only a
//! matter of cost (`cost` in the world crate's `trees.rs`).

use super::{NONE, NodeKind, Topology, children_in_order};

/// One piece of a tree cut by [`Topology::split`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Piece {
    /// Its shape.
    pub topology: Topology,
    /// The whole tree's body of each of its bodies.
    pub bodies: Vec<u32>,
    /// The whole tree's joint of each of its joints.
    pub joints: Vec<u32>,
    /// The whole tree's node of each of its nodes.
    pub nodes: Vec<u32>,
    /// For a piece cut off the trunk, the whole tree's node of the body it
    /// hangs from (`None` for the trunk).
    pub hangs_from: Option<u32>,
    /// For the trunk, the whole tree's node of each port's cut joint (in
    /// port order).
    pub ports: Vec<u32>,
}

impl Topology {
    /// How many nodes each node's subtree holds (itself included).
    pub fn subtree_sizes(&self) -> Vec<usize> {
        let mut sizes = vec![1usize; self.nodes.len()];
        for (n, node) in self.nodes.iter().enumerate() {
            if node.parent != NONE {
                sizes[node.parent as usize] += sizes[n];
            }
        }
        sizes
    }

    /// The joints to cut for pieces of at most `most` nodes: every joint
    /// below a body (not the root) whose subtree holds at most `most`
    /// nodes and whose parent's subtree holds more (the largest such
    /// subtrees), in elimination order.
    pub fn cuts(&self, most: usize) -> Vec<u32> {
        let sizes = self.subtree_sizes();
        let mut cuts = Vec::new();
        for (n, node) in self.nodes.iter().enumerate() {
            let below_body = node.parent != NONE
                && matches!(self.nodes[node.parent as usize].kind, NodeKind::Body { .. });
            if matches!(node.kind, NodeKind::Joint { .. })
                && below_body
                && sizes[n] <= most
                && sizes[node.parent as usize] > most
            {
                cuts.push(n as u32);
            }
        }
        cuts
    }

    /// The pieces the joints `cuts` (nodes, each a joint below a body, no
    /// two in one subtree) cut the tree into: each subtree they root, then
    /// the trunk, last. With no cuts, the whole tree is its one piece.
    pub fn split(&self, cuts: &[u32]) -> Vec<Piece> {
        let count = self.nodes.len();
        // Which piece each node falls in (`cuts.len()`: the trunk).
        let mut piece = vec![cuts.len(); count];
        for n in (0..count).rev() {
            if let Some(k) = cuts.iter().position(|&c| c as usize == n) {
                piece[n] = k;
            } else if self.nodes[n].parent != NONE {
                piece[n] = piece[self.nodes[n].parent as usize];
            }
        }
        let mut pieces: Vec<Piece> = (0..cuts.len())
            .map(|k| self.piece(&piece, k, Some(self.nodes[cuts[k] as usize].parent), &[]))
            .collect();
        pieces.push(self.piece(&piece, cuts.len(), None, cuts));
        pieces
    }

    /// Piece `k` of the nodes `piece` assigns: its bodies numbered as its
    /// joints (in the whole tree's order) name them, the trunk's root body
    /// first, its joints in the whole tree's order, and its topology built
    /// as a whole tree's is (a cut piece's root is its cut joint, whose
    /// trunk side is left as `None`).
    fn piece(&self, piece: &[usize], k: usize, hangs_from: Option<u32>, cuts: &[u32]) -> Piece {
        let inside = |n: u32| n != NONE && piece[n as usize] == k;
        let body_of = |n: u32| match self.nodes[n as usize].kind {
            NodeKind::Body { index } => index,
            NodeKind::Joint { .. } => unreachable!("a joint's side is a body"),
        };
        let mut joints: Vec<(u32, u32)> = (0..self.nodes.len() as u32)
            .filter(|&n| inside(n))
            .filter_map(|n| match self.nodes[n as usize].kind {
                NodeKind::Joint { index, .. } => Some((index, n)),
                NodeKind::Body { .. } => None,
            })
            .collect();
        joints.sort_unstable();
        let mut bodies: Vec<u32> = Vec::new();
        let root = self.nodes.len() as u32 - 1;
        if hangs_from.is_none() && matches!(self.nodes[root as usize].kind, NodeKind::Body { .. }) {
            bodies.push(body_of(root));
        }
        let mut shape = Vec::with_capacity(joints.len());
        for &(_, n) in &joints {
            let NodeKind::Joint { rows, a, b, .. } = self.nodes[n as usize].kind else {
                unreachable!("a joint node");
            };
            let mut local = |side: u32| -> Option<u32> {
                if !inside(side) {
                    return None;
                }
                let body = body_of(side);
                let at = bodies.iter().position(|&b| b == body).unwrap_or_else(|| {
                    bodies.push(body);
                    bodies.len() - 1
                });
                Some(at as u32)
            };
            let (a, b) = (local(a), local(b));
            shape.push((rows, a, b));
        }
        if joints.is_empty() {
            // A lone body (a trunk of one): no joint names it.
            bodies = (0..self.nodes.len() as u32)
                .filter(|&n| inside(n))
                .map(body_of)
                .collect();
        }
        let mut topology =
            Topology::new(bodies.len(), &shape).expect("a piece of a tree is a tree");
        let nodes: Vec<u32> = topology
            .nodes
            .iter()
            .map(|node| match node.kind {
                NodeKind::Body { index } => self.node_of_body(bodies[index as usize]),
                NodeKind::Joint { index, .. } => joints[index as usize].1,
            })
            .collect();
        if !cuts.is_empty() {
            // The trunk: children by the whole tree's joint indices, ports
            // where the cut joints were.
            let keys: Vec<u32> = nodes
                .iter()
                .map(|&n| match self.nodes[n as usize].kind {
                    NodeKind::Joint { index, .. } => index,
                    NodeKind::Body { .. } => 0,
                })
                .collect();
            let ports: Vec<(u32, u32, u32)> = cuts
                .iter()
                .enumerate()
                .map(|(p, &cut)| {
                    let parent = self.nodes[cut as usize].parent;
                    let at = nodes
                        .iter()
                        .position(|&n| n == parent)
                        .expect("cut below the trunk");
                    let NodeKind::Joint { index, .. } = self.nodes[cut as usize].kind else {
                        unreachable!("a cut is a joint");
                    };
                    (at as u32, index, p as u32)
                })
                .collect();
            let children = children_in_order(&topology.nodes, &keys, &ports);
            topology = Topology::with_children(
                topology.nodes,
                topology.bodies,
                topology.joints,
                children,
                cuts.len(),
            );
        }
        Piece {
            topology,
            bodies,
            joints: joints.iter().map(|&(index, _)| index).collect(),
            nodes,
            hangs_from,
            ports: cuts.to_vec(),
        }
    }

    /// The node of body `index`.
    fn node_of_body(&self, index: u32) -> u32 {
        let found = self
            .nodes
            .iter()
            .position(|n| n.kind == NodeKind::Body { index });
        found.expect("every body is a node") as u32
    }
}

/// Where one piece of a tree was laid out.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Placed {
    /// Its block (an index into the blocks [`lay_out`] returns).
    pub block: usize,
    /// Its lane.
    pub lane: usize,
    /// The piece.
    pub piece: Piece,
}

/// Lays out `trees` (each its whole topology and the joints to cut it at)
/// as pieces in blocks solved together: the pieces pooled by shape (the
/// limbs of every tree side by side, legs with arms where their shapes
/// agree), eight to a block, the blocks without ports first and the
/// trunks after; ports and parents name blocks by their place in the
/// returned list. Each piece's topology is found in `topologies` (the
/// caller's list, which its blocks' `topology` index) or added to it.
/// Returns the blocks (padding in every
/// lane but the placed ones, whose bodies and joints the caller sets) and
/// each tree's pieces.
pub fn lay_out(
    trees: &[(&Topology, Vec<u32>)],
    topologies: &mut Vec<Topology>,
) -> (Vec<super::TreeBlock>, Vec<Vec<Placed>>) {
    use super::{Port, Source, TreeBlock};
    use std::collections::BTreeMap;
    use vertebra_math::block::BLOCK_LANES;

    let split: Vec<Vec<Piece>> = trees.iter().map(|(t, cuts)| t.split(cuts)).collect();
    // Shapes in order first met, pieces without ports before trunks.
    let mut order: Vec<(bool, u32)> = Vec::new();
    let mut by_shape: BTreeMap<(bool, u32), Vec<(usize, usize)>> = BTreeMap::new();
    for (t, pieces) in split.iter().enumerate() {
        for (p, piece) in pieces.iter().enumerate() {
            let key = (
                piece.topology.ports > 0,
                intern(topologies, &piece.topology),
            );
            if !by_shape.contains_key(&key) {
                order.push(key);
            }
            by_shape.entry(key).or_default().push((t, p));
        }
    }
    order.sort_by_key(|&(trunk, _)| trunk);
    let mut blocks: Vec<TreeBlock> = Vec::new();
    let mut placed: Vec<Vec<Option<Placed>>> = split
        .iter()
        .map(|pieces| vec![None; pieces.len()])
        .collect();
    for key in order {
        for chunk in by_shape[&key].chunks(BLOCK_LANES) {
            let (t, p) = chunk[0];
            let topology = &split[t][p].topology;
            blocks.push(TreeBlock::padding(key.1, topology));
            for (lane, &(t, p)) in chunk.iter().enumerate() {
                placed[t][p] = Some(Placed {
                    block: blocks.len() - 1,
                    lane,
                    piece: split[t][p].clone(),
                });
            }
        }
    }
    let placed: Vec<Vec<Placed>> = placed
        .into_iter()
        .map(|pieces| {
            pieces
                .into_iter()
                .map(|p| p.expect("every piece placed"))
                .collect()
        })
        .collect();
    // Ports (trunk <- piece) and parents (piece <- trunk).
    for pieces in &placed {
        let trunk = pieces.last().expect("a tree has a trunk");
        for (k, cut) in trunk.piece.ports.iter().enumerate() {
            let hanging = pieces
                .iter()
                .find(|p| p.piece.nodes.last() == Some(cut))
                .expect("a piece for every cut");
            let root = hanging.piece.topology.nodes.len() - 1;
            let port: &mut Port = &mut blocks[trunk.block].ports[k];
            port.source[trunk.lane] = Some(Source {
                block: hanging.block as u32,
                lane: hanging.lane as u8,
                node: root as u32,
            });
            let from = hanging.piece.hangs_from.expect("a cut piece hangs");
            let at = trunk.piece.nodes.iter().position(|&n| n == from);
            blocks[hanging.block].parent[hanging.lane] = Some(Source {
                block: trunk.block as u32,
                lane: trunk.lane as u8,
                node: at.expect("it hangs from the trunk") as u32,
            });
        }
    }
    (blocks, placed)
}

/// `piece`'s index in `topologies`, added at the end if it is not there.
fn intern(topologies: &mut Vec<Topology>, piece: &Topology) -> u32 {
    let known = topologies.iter().position(|t| t == piece);
    known.unwrap_or_else(|| {
        topologies.push(piece.clone());
        topologies.len() - 1
    }) as u32
}
