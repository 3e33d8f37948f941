//! A seeded generator of corrupted telemetry: a clean simulated file, split into
//! fields, with a few structured mutations applied (numbers at and beyond the supported
//! range, NaN/inf text, sign flips, swapped columns, duplicated/dropped rows, truncated
//! lines, non-unit quaternions, glitches, time reversals and repeats).

/// SplitMix64: small, fast, and the same sequence on every platform.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed ^ 0x9e37_79b9_7f4a_7c15)
    }

    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// A CSV file as fields: the header, then the rows.
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn parse(text: &str) -> Self {
        let mut lines = text
            .lines()
            .map(|l| l.split(',').map(String::from).collect());
        let header = lines.next().unwrap_or_default();
        Self {
            header,
            rows: lines.collect(),
        }
    }

    pub fn to_csv(&self) -> String {
        let mut s = self.header.join(",");
        s.push('\n');
        for r in &self.rows {
            s.push_str(&r.join(","));
            s.push('\n');
        }
        s
    }

    fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    fn value(&self, row: usize, col: usize) -> f64 {
        self.rows[row]
            .get(col)
            .and_then(|f| f.parse().ok())
            .unwrap_or(0.0)
    }

    fn set(&mut self, row: usize, col: usize, v: f64) {
        if let Some(f) = self.rows[row].get_mut(col) {
            *f = format!("{v:?}");
        }
    }
}

/// Special field texts: zeros, tiny and huge numbers on both sides of the supported
/// range, non-numbers.
const SPECIAL: &[&str] = &[
    "0",
    "-0",
    "1e-300",
    "-1e-300",
    "5e-324",
    "1e-12",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e154",
    "1e20",
    "1e15",
    "1e6",
    "-1e6",
    "999999.9",
    "1e4",
    "-1e4",
    "100",
    "-100",
    "1e10",
    "-1e10",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "",
    " ",
    "abc",
    "1e",
    "0x10",
    "1,5",
];

const COLUMNS: &[&str] = &[
    "t", "q_x", "q_y", "q_z", "q_w", "rho_x", "rho_y", "rho_z", "tau_x", "tau_y", "tau_z", "w_x",
    "w_y", "w_z",
];

/// Apply 1–4 mutations to `t`.
pub fn mutate(t: &mut Table, rng: &mut Rng) {
    let n = 1 + rng.below(4);
    for _ in 0..n {
        if t.rows.len() < 2 {
            return;
        }
        let row = rng.below(t.rows.len());
        let width = t.header.len();
        let col = rng.below(width);
        match rng.below(16) {
            0 | 1 => {
                let v = *rng.pick(SPECIAL);
                if let Some(f) = t.rows[row].get_mut(col) {
                    *f = v.to_string();
                }
            }
            2 => {
                // A value at or just inside a limit, over a run of rows.
                let name = *rng.pick(&COLUMNS[5..]);
                if let Some(c) = t.column(name) {
                    let limit = match &name[..1] {
                        "r" => 1e6,
                        "t" => 1e4,
                        _ => 100.0,
                    };
                    let v = limit
                        * if rng.chance(0.5) { 1.0 } else { -1.0 }
                        * (1.0 - rng.unit() * 1e-3);
                    let len = 1 + rng.below(20);
                    for r in row..(row + len).min(t.rows.len()) {
                        t.set(r, c, v);
                    }
                }
            }
            3 => {
                let v = -t.value(row, col);
                t.set(row, col, v);
            }
            4 => {
                // Swapped columns, in one row or in the header.
                let other = rng.below(width);
                if rng.chance(0.2) {
                    t.header.swap(col, other);
                } else if col.max(other) < t.rows[row].len() {
                    t.rows[row].swap(col, other);
                }
            }
            5 => {
                let copy = t.rows[row].clone();
                t.rows.insert(row, copy);
            }
            6 => {
                let most = if rng.chance(0.2) { 100 } else { 3 };
                let len = 1 + rng.below(most);
                let end = (row + len).min(t.rows.len());
                t.rows.drain(row..end);
            }
            7 => {
                let keep = rng.below(width);
                t.rows[row].truncate(keep);
            }
            8 => {
                // Break the unit norm of the quaternion.
                let f = *rng.pick(&[1.0005, 0.9995, 1.0011, 1.01, 0.0, -1.0, 2.0]);
                for name in &COLUMNS[1..5] {
                    if let Some(c) = t.column(name) {
                        let v = t.value(row, c) * f;
                        t.set(row, c, v);
                    }
                }
            }
            9 => {
                // A glitch: an offset on a run of rows.
                let scale = *rng.pick(&[1e-6, 1e-2, 1.0, 1e2, 1e4]);
                let v0 = (rng.unit() - 0.5) * scale;
                let len = 1 + rng.below(10);
                for r in row..(row + len).min(t.rows.len()) {
                    let v = t.value(r, col) + v0;
                    t.set(r, col, v);
                }
            }
            10 => {
                // Time reversal or a repeated time stamp.
                if row + 1 < t.rows.len() && !t.rows[row].is_empty() && !t.rows[row + 1].is_empty()
                {
                    if rng.chance(0.5) {
                        let (a, b) = (t.rows[row][0].clone(), t.rows[row + 1][0].clone());
                        t.rows[row][0] = b;
                        t.rows[row + 1][0] = a;
                    } else {
                        t.rows[row + 1][0] = t.rows[row][0].clone();
                    }
                }
            }
            11 => {
                // A tiny or large step: shift all later times.
                let dt = *rng.pick(&[1e-9, 1e-6, 1e-3, 0.35, 3.0, 1e3, 1e9]);
                let prev = if row > 0 { t.value(row - 1, 0) } else { 0.0 };
                let shift = prev + dt - t.value(row, 0);
                for r in row..t.rows.len() {
                    let v = t.value(r, 0) + shift;
                    t.set(r, 0, v);
                }
            }
            12 => {
                // q → −q on a run of rows.
                let len = 1 + rng.below(30);
                for r in row..(row + len).min(t.rows.len()) {
                    for c in 1..5 {
                        let v = -t.value(r, c);
                        t.set(r, c, v);
                    }
                }
            }
            13 => {
                // Scale a whole column (units mistakes: deg for rad, mN m s, …).
                let f = *rng.pick(&[0.0, 1e-3, 57.29577951308232, 1e3, -1.0]);
                for r in 0..t.rows.len() {
                    let v = t.value(r, col) * f;
                    t.set(r, col, v);
                }
            }
            14 => {
                // Keep only the first rows.
                let keep = 1 + rng.below(12);
                t.rows.truncate(keep);
            }
            _ => {
                // Random-magnitude number.
                let e = rng.below(40) as i32 - 20;
                let v = (rng.unit() - 0.5) * 10f64.powi(e);
                t.set(row, col, v);
            }
        }
    }
}
