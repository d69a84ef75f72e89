//! The block grid laid over an image, and which blocks hold fixed pixels.

/// One coding block: its top-left pixel and size (edge blocks may be smaller than the block side).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct BlockRect {
    pub x0: usize,
    pub y0: usize,
    pub w: usize,
    pub h: usize,
}

/// The blocks of a `width × height` image in raster order.
#[derive(Debug, Clone)]
pub(crate) struct BlockGrid {
    pub width: usize,
    pub height: usize,
    pub block: usize,
    pub cols: usize,
    pub rows: usize,
}

impl BlockGrid {
    pub fn new(width: usize, height: usize, block: usize) -> Self {
        BlockGrid {
            width,
            height,
            block,
            cols: width.div_ceil(block),
            rows: height.div_ceil(block),
        }
    }

    pub fn len(&self) -> usize {
        self.cols * self.rows
    }

    pub fn rect(&self, index: usize) -> BlockRect {
        let (bx, by) = (index % self.cols, index / self.cols);
        let (x0, y0) = (bx * self.block, by * self.block);
        BlockRect {
            x0,
            y0,
            w: self.block.min(self.width - x0),
            h: self.block.min(self.height - y0),
        }
    }

    /// Row-major pixel indices of a block, row by row.
    pub fn pixels(&self, rect: BlockRect) -> impl Iterator<Item = usize> + '_ {
        (rect.y0..rect.y0 + rect.h)
            .flat_map(move |y| (rect.x0..rect.x0 + rect.w).map(move |x| y * self.width + x))
    }

    /// The pixels of block `rect` set in `mask`, as bits of an 8 × 8 block: bit `y * 8 + x` for
    /// the block's pixel (x, y); pixels of a partial edge block outside the image are clear.
    pub fn block_mask(&self, rect: BlockRect, mask: &[bool]) -> u64 {
        let mut bits = 0u64;
        for (i, pixel) in self.pixels(rect).enumerate() {
            if mask[pixel] {
                bits |= 1 << ((i / rect.w) * 8 + i % rect.w);
            }
        }
        bits
    }

    /// For each block, whether it holds at least one pixel with `mask` set.
    pub fn any_set(&self, mask: &[bool]) -> Vec<bool> {
        (0..self.len())
            .map(|b| self.pixels(self.rect(b)).any(|i| mask[i]))
            .collect()
    }
}
