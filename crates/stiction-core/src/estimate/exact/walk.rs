/// The cell of the Stenman partition that contains `d`: the range of d values whose valve
/// trajectory driven by `op` from the valve position `x0` at the first sample is the same as d's,
/// clipped to `[lo, hi)`. One pass over the data:
/// the trajectory stays the same while every sticking step keeps `|u - x| <= d` and every slip
/// keeps `|u - x| > d`. The trajectory itself is written to `mv`.
// kept out of line: inlined into the walk, its loop variables were spilled to the stack
#[inline(never)]
pub fn stenman_cell_into(
    op: &[f64],
    x0: f64,
    d: f64,
    lo: f64,
    hi: f64,
    mv: &mut [f64],
) -> (f64, f64) {
    let (mut a, mut b) = (lo, hi);
    let mut x = x0;
    mv[0] = x;
    for (&u, m) in op[1..].iter().zip(&mut mv[1..]) {
        let delta = (u - x).abs();
        let slips = delta > d;
        // plain comparisons, not f64::min/max: the data are finite, and the NaN handling of
        // min/max would sit on the loop-carried chains
        b = if slips && delta < b { delta } else { b };
        a = if !slips && delta > a { delta } else { a };
        x = if slips { u } else { x };
        *m = x;
    }
    (a, b)
}

/// Walk every cell of the Stenman partition of `[a, b)` (within the search range `[lo, hi)`) in
/// order of d, handing each cell and its valve trajectory to `visit`. The valve stands at `x0` at
/// the first sample.
pub fn stenman_walk(
    op: &[f64],
    x0: f64,
    (a, b): (f64, f64),
    (lo, hi): (f64, f64),
    mv: &mut [f64],
    mut visit: impl FnMut((f64, f64), &mut [f64]),
) {
    let mut d = a;
    while d < b {
        let (ca, cb) = stenman_cell_into(op, x0, d, lo, hi, mv);
        // the piece of the cell inside [a, b): cells that cross a chunk edge are visited in parts
        visit((ca.max(a), cb.min(b)), mv);
        if cb <= d {
            break; // cannot happen for d in [lo, hi); guards against an endless loop
        }
        d = cb;
    }
}

/// Steps per block of the walker's per-block extremes.
const BLOCK: usize = 32;

/// [`stenman_walk`] that also says where each cell's trajectory differs from the previous
/// cell's: `visit` gets the cell, the trajectory and the samples that changed, in increasing order
/// (`None` for the first cell, which has no previous one). The same cells and trajectories as
/// [`stenman_walk`], bit for bit, at a cost that follows the changes: the next cell's trajectory is
/// the same up to the step whose slip ended the cell (the first step with the smallest slipping
/// `|u - x|`), and once the valve stands where it stood before, the rest is the same again, so only
/// that stretch is simulated again. Each step's `|u - x|` is kept, split by whether it sticks or
/// slips, with their extremes per block of steps, from which the cell's edges follow.
pub fn stenman_walk_changes(
    op: &[f64],
    x0: f64,
    (a, b): (f64, f64),
    (lo, hi): (f64, f64),
    mut visit: impl FnMut((f64, f64), &[f64], Option<&[usize]>),
) {
    if op.is_empty() || a >= b {
        return;
    }
    let mut walker = Walker::new(op, x0, a, (lo, hi));
    let (ca, mut cb) = walker.edges();
    visit((ca.max(a), cb.min(b)), &walker.x, None);
    while cb < b {
        walker.advance(cb);
        let (ca, next) = walker.edges();
        if next <= cb {
            break; // cannot happen for d in [lo, hi); guards against an endless loop
        }
        cb = next;
        visit((ca.max(a), cb.min(b)), &walker.x, Some(&walker.changed));
    }
}

/// One walk's state: the trajectory, each step's `|u - x|` as a sticking or a slipping step
/// (the other set to -inf / +inf), their extremes per block, and the last change.
struct Walker<'a> {
    op: &'a [f64],
    lo: f64,
    hi: f64,
    x: Vec<f64>,
    stick: Vec<f64>,
    slip: Vec<f64>,
    block_stick: Vec<f64>,
    block_slip: Vec<f64>,
    changed: Vec<usize>,
}

impl<'a> Walker<'a> {
    /// The trajectory of band `d`, simulated whole.
    fn new(op: &'a [f64], x0: f64, d: f64, (lo, hi): (f64, f64)) -> Self {
        let n = op.len();
        let blocks = n.div_ceil(BLOCK);
        let mut w = Self {
            op,
            lo,
            hi,
            x: vec![x0; n],
            stick: vec![f64::NEG_INFINITY; n],
            slip: vec![f64::INFINITY; n],
            block_stick: vec![f64::NEG_INFINITY; blocks],
            block_slip: vec![f64::INFINITY; blocks],
            changed: Vec::new(),
        };
        let mut x = x0;
        for i in 1..n {
            x = w.step(i, x, d);
            w.x[i] = x;
        }
        w.refresh_blocks(0, blocks);
        w
    }

    /// Step `i` of band `d` from the valve position `x`: whether it sticks or slips (its
    /// `|u - x|` kept as such), and where the valve stands after it.
    #[inline]
    fn step(&mut self, i: usize, x: f64, d: f64) -> f64 {
        let u = self.op[i];
        let delta = (u - x).abs();
        if delta > d {
            self.slip[i] = delta;
            self.stick[i] = f64::NEG_INFINITY;
            u
        } else {
            self.stick[i] = delta;
            self.slip[i] = f64::INFINITY;
            x
        }
    }

    fn refresh_blocks(&mut self, from: usize, to: usize) {
        let n = self.x.len();
        for k in from..to {
            let r = k * BLOCK..((k + 1) * BLOCK).min(n);
            self.block_stick[k] = self.stick[r.clone()]
                .iter()
                .fold(f64::NEG_INFINITY, |m, &v| if v > m { v } else { m });
            self.block_slip[k] = self.slip[r]
                .iter()
                .fold(f64::INFINITY, |m, &v| if v < m { v } else { m });
        }
    }

    /// The cell's edges: the largest sticking and the smallest slipping `|u - x|`, within
    /// `[lo, hi)`, as [`stenman_cell_into`] finds them.
    fn edges(&self) -> (f64, f64) {
        let a = self
            .block_stick
            .iter()
            .fold(self.lo, |m, &v| if v > m { v } else { m });
        let b = self
            .block_slip
            .iter()
            .fold(self.hi, |m, &v| if v < m { v } else { m });
        (a, b)
    }

    /// Move to the next cell, band `d` (the previous cell's upper edge): the steps whose slip
    /// ended at `d` stick now, the first of them and the last bound the stretch that must be
    /// simulated again, which runs on until the valve stands where it stood before.
    fn advance(&mut self, d: f64) {
        self.changed.clear();
        let Some(first_block) = self.block_slip.iter().position(|&v| v == d) else {
            return;
        };
        let last_block = self
            .block_slip
            .iter()
            .rposition(|&v| v == d)
            .unwrap_or(first_block);
        let n = self.x.len();
        let start = (first_block * BLOCK..((first_block + 1) * BLOCK).min(n))
            .find(|&i| self.slip[i] == d)
            .expect("the block's smallest slip is one of its steps");
        // every tie lies before this step
        let ties_end = ((last_block + 1) * BLOCK).min(n);
        let mut x = self.x[start - 1];
        let mut end = n;
        for i in start..n {
            x = self.step(i, x, d);
            if x.to_bits() != self.x[i].to_bits() {
                self.x[i] = x;
                self.changed.push(i);
            } else if i + 1 >= ties_end {
                // the valve stands where it stood: the rest is the same
                end = i + 1;
                break;
            }
        }
        self.refresh_blocks(start / BLOCK, end.div_ceil(BLOCK));
    }
}
