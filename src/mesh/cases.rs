//! The surface's pieces inside one grid cell, for each of the 256 ways
//! its eight corners can be inside or outside.
//!
//! A cell's crossing edges (those whose corners disagree) join into loops
//! along the cell's faces, as marching cubes' polygons do: on a face with
//! two crossing edges the two join; on a face with four (inside corners on
//! one diagonal, outside on the other) each inside corner is cut off by
//! its own segment, so the outside stays connected across the face. Both
//! cells that share a face read it the same way. Giving each loop its own
//! vertex keeps two sheets that pass through one cell from sharing an
//! edge; an edge still joins four faces where one piece on each side of a
//! face touches it along two separate segments, which no dual mesh can
//! represent (rare, and only in features smaller than a cell).

use std::sync::OnceLock;

/// Corner `i` of a cell lies at offset `(i & 1, i >> 1 & 1, i >> 2)`.
pub(crate) const fn corner(i: usize) -> [u32; 3] {
    [(i & 1) as u32, (i >> 1 & 1) as u32, (i >> 2) as u32]
}

/// The cell's 12 edges as pairs of corners `(a, a | bit)`.
pub(crate) const EDGES: [(usize, usize); 12] = {
    let mut out = [(0, 0); 12];
    let mut n = 0;
    let mut a = 0;
    while a < 8 {
        let mut bit = 1;
        while bit < 8 {
            if a & bit == 0 {
                out[n] = (a, a | bit);
                n += 1;
            }
            bit <<= 1;
        }
        a += 1;
    }
    out
};

/// The edge joining corners `a` and `b`.
pub(crate) fn edge(a: usize, b: usize) -> usize {
    let (a, b) = (a.min(b), a.max(b));
    EDGES
        .iter()
        .position(|&e| e == (a, b))
        .expect("corners that differ in one bit")
}

/// Each face's corners, in order around it.
const FACES: [[usize; 4]; 6] = [
    [0, 2, 6, 4],
    [1, 3, 7, 5],
    [0, 1, 5, 4],
    [2, 3, 7, 6],
    [0, 1, 3, 2],
    [4, 5, 7, 6],
];

/// The pieces of one case: the piece each edge belongs to (`NONE` where
/// the edge does not cross), and how many pieces there are.
#[derive(Clone, Copy)]
pub(crate) struct Case {
    pub piece: [u8; 12],
    pub pieces: u8,
}

/// An edge the surface does not cross.
pub(crate) const NONE: u8 = u8::MAX;

/// The case of the cell whose inside corners are the set bits of `mask`.
pub(crate) fn case(mask: u8) -> &'static Case {
    static TABLE: OnceLock<Vec<Case>> = OnceLock::new();
    &TABLE.get_or_init(|| (0..=255).map(build).collect())[usize::from(mask)]
}

fn build(mask: u8) -> Case {
    let inside = |c: usize| mask >> c & 1 == 1;
    let crosses = |e: usize| inside(EDGES[e].0) != inside(EDGES[e].1);
    let mut parent: [usize; 12] = std::array::from_fn(|e| e);
    fn root(parent: &mut [usize; 12], mut e: usize) -> usize {
        while parent[e] != e {
            parent[e] = parent[parent[e]];
            e = parent[e];
        }
        e
    }
    let mut join = |a: usize, b: usize| {
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        parent[ra] = rb;
    };
    for face in FACES {
        let sides: [usize; 4] = std::array::from_fn(|i| edge(face[i], face[(i + 1) % 4]));
        let crossing: Vec<usize> = sides.iter().copied().filter(|&e| crosses(e)).collect();
        match crossing.len() {
            2 => join(crossing[0], crossing[1]),
            4 => {
                // Cut off each inside corner: its two sides meet there.
                for i in 0..4 {
                    if inside(face[i]) {
                        join(sides[(i + 3) % 4], sides[i]);
                    }
                }
            }
            _ => {}
        }
    }
    let mut piece = [NONE; 12];
    let mut roots: Vec<usize> = Vec::new();
    for (e, slot) in piece.iter_mut().enumerate() {
        if crosses(e) {
            let r = root(&mut parent, e);
            let id = roots.iter().position(|&x| x == r).unwrap_or_else(|| {
                roots.push(r);
                roots.len() - 1
            });
            *slot = u8::try_from(id).expect("at most 4 pieces");
        }
    }
    Case {
        piece,
        pieces: u8::try_from(roots.len()).expect("at most 4 pieces"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_join_corners_one_step_apart() {
        for (a, b) in EDGES {
            assert_eq!((a ^ b).count_ones(), 1);
        }
        for face in FACES {
            for i in 0..4 {
                let _ = edge(face[i], face[(i + 1) % 4]);
            }
        }
    }

    #[test]
    fn pieces_match_marching_cubes() {
        // Empty and full cells have none.
        assert_eq!(case(0).pieces, 0);
        assert_eq!(case(255).pieces, 0);
        // One corner inside: one triangle around it.
        assert_eq!(case(0b0000_0001).pieces, 1);
        // Two opposite corners of the cube: two separate triangles.
        assert_eq!(case(0b1000_0001).pieces, 2);
        // Two corners on a face's diagonal: separated across the face.
        assert_eq!(case(0b0000_1001).pieces, 2);
        // Its complement: the outside corners are the ones cut off.
        assert_eq!(case(0b1111_0110).pieces, 1);
        // Four corners of one face: one quad.
        assert_eq!(case(0b0000_1111).pieces, 1);
        // Every case: each crossing edge in a piece, 3 to 12 per piece.
        for mask in 0..=255u8 {
            let c = case(mask);
            for p in 0..c.pieces {
                let n = c.piece.iter().filter(|&&x| x == p).count();
                assert!(
                    (3..=12).contains(&n),
                    "case {mask:#010b}, piece {p}: {n} edges"
                );
            }
        }
    }
}
