//! Snapshot storage on the cell grid: positions sorted by cell (a counting
//! sort), each cell's items contiguous with their positions.

use super::CellGrid;

/// Items binned by cell (see [`Bins::fill`]); buffers reused.
#[derive(Debug, Clone, Default)]
pub(crate) struct Bins {
    /// Cell `f` holds `items[start[f]..start[f + 1]]`.
    pub(crate) start: Vec<u32>,
    /// `(item, position)`.
    pub(crate) items: Vec<(u32, [f64; 3])>,
    /// Cell of every item, and the fill pointers (scratch).
    cell: Vec<u32>,
    fill: Vec<u32>,
}

impl Bins {
    /// Bins `centers` by cell of `grid` (each cell's items in index order,
    /// with their centres, contiguous).
    pub(crate) fn fill(&mut self, grid: &CellGrid, centers: &[[f64; 3]]) {
        let cells = grid.cells();
        self.cell.clear();
        self.cell
            .extend(centers.iter().map(|c| grid.index(c) as u32));
        self.start.clear();
        self.start.resize(cells + 1, 0);
        for &f in &self.cell {
            self.start[f as usize + 1] += 1;
        }
        for f in 0..cells {
            self.start[f + 1] += self.start[f];
        }
        self.items.clear();
        self.items.resize(centers.len(), (0, [0.0; 3]));
        let mut fill = std::mem::take(&mut self.fill);
        fill.clear();
        fill.extend_from_slice(&self.start[..cells]);
        for (p, &f) in self.cell.iter().enumerate() {
            let k = &mut fill[f as usize];
            self.items[*k as usize] = (p as u32, centers[p]);
            *k += 1;
        }
        self.fill = fill;
    }
}
