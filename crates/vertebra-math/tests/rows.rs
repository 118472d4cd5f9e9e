//! Body-row gather and scatter: every backend moves exactly the scalar
//! reference's bits, and skips `NO_WRITE` lanes.

mod common;

use common::{random_float, rng};
use rand::RngExt;
use vertebra_math::row::{NO_WRITE, ROW_LEN, Row};
use vertebra_math::{Backend, Lane, LaneKernel};

/// Gathers `reads` in lane-width groups, adds `k + 1` to element `k`, and
/// scatters to `writes`.
struct Shift<'a> {
    rows: &'a [Row],
    reads: &'a [u32],
    writes: &'a [u32],
}

impl LaneKernel for Shift<'_> {
    type Output = Vec<[f32; 8]>;
    #[inline(always)]
    fn run<L: Lane>(self) -> Vec<[f32; 8]> {
        let mut gathered = Vec::new();
        for start in (0..self.reads.len()).step_by(L::WIDTH) {
            let mut values = L::gather_rows(self.rows, &self.reads[start..]);
            let mut columns = [[0.0f32; 8]; ROW_LEN];
            for (k, v) in values.iter_mut().enumerate() {
                v.store(&mut columns[k]);
                *v += L::splat(k as f32 + 1.0);
            }
            gathered.extend((0..L::WIDTH).map(|lane| core::array::from_fn(|k| columns[k][lane])));
            L::scatter_rows(&values, self.rows, &self.writes[start..]);
        }
        gathered
    }
}

fn bits(rows: &[Row]) -> Vec<[u32; 8]> {
    rows.iter().map(|r| r.get().map(f32::to_bits)).collect()
}

#[test]
fn gather_and_scatter_move_the_same_bits_on_every_backend() {
    let mut r = rng(41);
    for trial in 0..200 {
        let n = r.random_range(1..40);
        let initial: Vec<[f32; 8]> = (0..n)
            .map(|_| core::array::from_fn(|_| random_float(&mut r)))
            .collect();
        // 8 lanes' worth (the widest backend), as the colouring builds
        // them: a written (dynamic) row is read by its own lane only; rows
        // that are never written (static, kinematic) may be read by many.
        let mut order: Vec<u32> = (0..n as u32).collect();
        for i in (1..order.len()).rev() {
            order.swap(i, r.random_range(0..=i));
        }
        let dynamic = &order[..n.min(8) / 2];
        let fixed = &order[n.min(8) / 2..];
        let mut reads = Vec::new();
        let mut writes = Vec::new();
        for lane in 0..8 {
            if lane < dynamic.len() && r.random_bool(0.8) {
                reads.push(dynamic[lane]);
                writes.push(dynamic[lane]);
            } else {
                reads.push(fixed[r.random_range(0..fixed.len())]);
                writes.push(NO_WRITE);
            }
        }
        let run = |backend: Backend| {
            let rows: Vec<Row> = initial.iter().map(|v| Row::new(*v)).collect();
            let gathered = backend.dispatch(Shift {
                rows: &rows,
                reads: &reads,
                writes: &writes,
            });
            (
                gathered
                    .iter()
                    .map(|g| g.map(f32::to_bits))
                    .collect::<Vec<_>>(),
                bits(&rows),
            )
        };
        let (expected_gather, expected_rows) = run(Backend::Scalar);
        for (lane, &read) in reads.iter().enumerate() {
            assert_eq!(
                expected_gather[lane],
                initial[read as usize].map(f32::to_bits)
            );
        }
        for (index, row) in expected_rows.iter().enumerate() {
            if !writes.contains(&(index as u32)) {
                assert_eq!(
                    *row,
                    initial[index].map(f32::to_bits),
                    "untouched row {index}"
                );
            }
        }
        for backend in Backend::available() {
            let (gather, rows) = run(backend);
            // NaN payloads may differ after the addition; compare through same_bits.
            let same = |a: &[[u32; 8]], b: &[[u32; 8]]| {
                a.iter().zip(b).all(|(x, y)| {
                    x.iter().zip(y).all(|(&x, &y)| {
                        vertebra_math::check::same_bits(f32::from_bits(x), f32::from_bits(y))
                    })
                })
            };
            assert!(
                same(&gather, &expected_gather),
                "{backend} gather, trial {trial}"
            );
            assert!(
                same(&rows, &expected_rows),
                "{backend} scatter, trial {trial}"
            );
        }
    }
}

/// Whether [`Shift`] over four rows with these indices panics on `backend`.
fn panics(backend: Backend, reads: [u32; 8], writes: [u32; 8]) -> bool {
    let rows: Vec<Row> = (0..4).map(|_| Row::new([1.0; 8])).collect();
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        backend.dispatch(Shift {
            rows: &rows,
            reads: &reads,
            writes: &writes,
        })
    }))
    .is_err()
}

/// The AVX gather and scatter check a slice's indices once, by their
/// maximum, and then index unchecked: an index past the rows must still
/// panic on every backend, in any lane, and `NO_WRITE` must not.
#[test]
fn indices_past_the_rows_panic_on_every_backend() {
    let inside = [3, 2, 1, 0, 0, 1, 2, 3];
    let none = [NO_WRITE; 8];
    let mut cases = Vec::new();
    for lane in 0..8 {
        let mut read_past = inside;
        read_past[lane] = 4;
        let (mut write_past, mut write_far) = (none, none);
        write_past[lane] = 4;
        write_far[lane] = u32::MAX - 1;
        cases.extend([
            (format!("lane {lane}: read past"), read_past, none, true),
            (format!("lane {lane}: write past"), inside, write_past, true),
            (format!("lane {lane}: write far"), inside, write_far, true),
        ]);
    }
    cases.push(("in range, no writes".into(), inside, none, false));
    cases.push(("in range, writes".into(), inside, inside, false));
    // The expected panics stay quiet; the hook is back before asserting.
    let prior = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let cases = &cases;
    let outcomes: Vec<_> = Backend::available()
        .flat_map(move |backend| {
            cases.iter().map(move |(what, reads, writes, expected)| {
                (backend, what, panics(backend, *reads, *writes), *expected)
            })
        })
        .collect();
    std::panic::set_hook(prior);
    for (backend, what, panicked, expected) in outcomes {
        assert_eq!(panicked, expected, "{backend}, {what}");
    }
}
