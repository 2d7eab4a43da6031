//! (Z − 1cᵀ)ᵀ(Z − 1cᵀ) for a tall, narrow block of columns Z shifted by a constant per column:
//! the cross-products of the shifted-data algorithm ([`super::Accumulator`]). The columns are
//! read where they are (the term evaluator's output, a user's matrix) and shifted in registers,
//! not copied first (the copy had cost ~6 % of a 2 505-row fit). Only the lower triangle is
//! computed (half the flops of a general product, as BLAS dsyrk); [`mirror`] completes it where
//! a full matrix is wanted. On x86-64 register-tiled kernels with explicit intrinsics (AVX-512, else AVX2+FMA, checked at
//! run time); elsewhere a portable one.

const LANES: usize = 4;

/// C (m × m, column-major) = ZᵀZ for Z of `n` rows, `m` columns, leading dimension `ld`.
pub fn gram(z: &[f64], ld: usize, n: usize, m: usize, c: &mut [f64]) {
    assert!(n <= ld && z.len() >= ld * (m.max(1) - 1) + n && c.len() == m * m, "gram: buffer sizes");
    let columns: Vec<&[f64]> = (0..m).map(|j| &z[j * ld..j * ld + n]).collect();
    c.fill(0.0);
    gram_add(&columns, &vec![0.0; m], c, &mut vec![0.0; m]);
    mirror(c, m);
}

/// Adds Σ_r (z_i[r] − c_i)(z_j[r] − c_j) to `c[i + j m]` for i ≥ j (and to the upper entries
/// of the diagonal 3 × 3 tiles, which [`mirror`] overwrites), and Σ_r (z_i[r] − c_i) to
/// `sums[i]`: m = `columns.len()`, all columns of one length. The sums come from the diagonal
/// tiles' loads on the otherwise idle add ports (a pass of their own cost a tenth of a fit).
pub fn gram_add(columns: &[&[f64]], shift: &[f64], c: &mut [f64], sums: &mut [f64]) {
    let m = columns.len();
    let n = columns.first().map_or(0, |z| z.len());
    assert!(
        shift.len() == m && sums.len() == m && c.len() == m * m && columns.iter().all(|z| z.len() == n),
        "gram_add: m columns of one length, m shifts and sums, m × m output"
    );
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        if has!("avx2") && has!("fma") {
            let ptrs: Vec<*const f64> = columns.iter().map(|z| z.as_ptr()).collect();
            // SAFETY: the CPU supports the features each function is compiled for; every
            // pointer is to a column of n values.
            unsafe {
                if has!("avx512f") {
                    gram_avx512(&ptrs, n, shift, c, sums);
                } else {
                    gram_avx2(&ptrs, n, shift, c, sums);
                }
            }
            return;
        }
    }
    gram_tiles(columns, n, shift, c, sums);
}

/// The lower triangle is exact; diagonal tiles also wrote some upper entries: overwrite them.
pub fn mirror(c: &mut [f64], m: usize) {
    for j in 0..m {
        for i in 0..j {
            c[i + j * m] = c[j + i * m];
        }
    }
}

/// Rows per panel. Each 3 × 3 tile reads six columns of the panel (256 × 8 bytes × 6 = 12 KB,
/// in L1) and the whole panel (≤ 64 KB for m ≤ 32) stays in L2 while all tiles pass over it;
/// every tile ends a panel with nine horizontal sums, so longer panels pay fewer of them
/// (256 rows: 6 % faster per 2 505-row fit than 128, measured with criterion).
#[cfg(target_arch = "x86_64")]
const PANEL: usize = 256;

/// The AVX2+FMA kernel. 3 × 3 output tiles: 9 accumulators + 3 loaded columns + 1 in the 16
/// vector registers; the six broadcast shifts do not fit beside them and are re-read from L1,
/// which the load ports absorb. The shift subtractions run on the FP add ports, so the FMAs stay the bottleneck.
#[cfg(target_arch = "x86_64")]
macro_rules! gram_kernel {
    ($name:ident, $features:literal) => {
        #[target_feature(enable = $features)]
        unsafe fn $name(z: &[*const f64], n: usize, shift: &[f64], c: &mut [f64], sums: &mut [f64]) {
            use std::arch::x86_64::*;
            #[inline(always)]
            unsafe fn hsum(v: __m256d) -> f64 {
                let mut lanes = [0.0f64; 4];
                _mm256_storeu_pd(lanes.as_mut_ptr(), v);
                (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
            }
            let m = z.len();
            let nq = n / 4 * 4;
            let mut r0 = 0;
            while r0 < nq {
                let r1 = (r0 + PANEL).min(nq);
                let mut j0 = 0;
                while j0 < m {
                    let mut i0 = j0;
                    while i0 < m {
                        if m - j0 >= 3 && m - i0 >= 3 {
                            let xi = [z[i0], z[i0 + 1], z[i0 + 2]];
                            let xj = [z[j0], z[j0 + 1], z[j0 + 2]];
                            let si = [
                                _mm256_set1_pd(shift[i0]),
                                _mm256_set1_pd(shift[i0 + 1]),
                                _mm256_set1_pd(shift[i0 + 2]),
                            ];
                            let sj = [
                                _mm256_set1_pd(shift[j0]),
                                _mm256_set1_pd(shift[j0 + 1]),
                                _mm256_set1_pd(shift[j0 + 2]),
                            ];
                            let mut acc = [[_mm256_setzero_pd(); 3]; 3];
                            let mut r = r0;
                            if i0 == j0 {
                                let mut sum = [_mm256_setzero_pd(); 3];
                                while r < r1 {
                                    let a = [
                                        _mm256_sub_pd(_mm256_loadu_pd(xi[0].add(r)), si[0]),
                                        _mm256_sub_pd(_mm256_loadu_pd(xi[1].add(r)), si[1]),
                                        _mm256_sub_pd(_mm256_loadu_pd(xi[2].add(r)), si[2]),
                                    ];
                                    for ai in 0..3 {
                                        sum[ai] = _mm256_add_pd(sum[ai], a[ai]);
                                        for bj in 0..3 {
                                            acc[ai][bj] = _mm256_fmadd_pd(a[ai], a[bj], acc[ai][bj]);
                                        }
                                    }
                                    r += 4;
                                }
                                for (ai, v) in sum.iter().enumerate() {
                                    sums[i0 + ai] += hsum(*v);
                                }
                            } else {
                                while r < r1 {
                                    let a = [
                                        _mm256_sub_pd(_mm256_loadu_pd(xi[0].add(r)), si[0]),
                                        _mm256_sub_pd(_mm256_loadu_pd(xi[1].add(r)), si[1]),
                                        _mm256_sub_pd(_mm256_loadu_pd(xi[2].add(r)), si[2]),
                                    ];
                                    for bj in 0..3 {
                                        let b = _mm256_sub_pd(_mm256_loadu_pd(xj[bj].add(r)), sj[bj]);
                                        for ai in 0..3 {
                                            acc[ai][bj] = _mm256_fmadd_pd(a[ai], b, acc[ai][bj]);
                                        }
                                    }
                                    r += 4;
                                }
                            }
                            for (ai, row) in acc.iter().enumerate() {
                                for (bj, v) in row.iter().enumerate() {
                                    c[(i0 + ai) + (j0 + bj) * m] += hsum(*v);
                                }
                            }
                        } else {
                            // edge tiles: one output at a time, still four lanes wide
                            for a in i0..m.min(i0 + 3) {
                                for b in j0..m.min(j0 + 3) {
                                    let (x, y) = (z[a], z[b]);
                                    let (sx, sy) = (_mm256_set1_pd(shift[a]), _mm256_set1_pd(shift[b]));
                                    let (mut acc, mut sum) = (_mm256_setzero_pd(), _mm256_setzero_pd());
                                    let mut r = r0;
                                    while r < r1 {
                                        let dx = _mm256_sub_pd(_mm256_loadu_pd(x.add(r)), sx);
                                        sum = _mm256_add_pd(sum, dx);
                                        let dy = _mm256_sub_pd(_mm256_loadu_pd(y.add(r)), sy);
                                        acc = _mm256_fmadd_pd(dx, dy, acc);
                                        r += 4;
                                    }
                                    c[a + b * m] += hsum(acc);
                                    if a == b {
                                        sums[a] += hsum(sum);
                                    }
                                }
                            }
                        }
                        i0 += 3;
                    }
                    j0 += 3;
                }
                r0 = r1;
            }
            for j in 0..m {
                for i in j..m {
                    let (x, y) = (z[i], z[j]);
                    for r in nq..n {
                        let (dx, dy) = (*x.add(r) - shift[i], *y.add(r) - shift[j]);
                        c[i + j * m] = dx.mul_add(dy, c[i + j * m]);
                    }
                }
                for r in nq..n {
                    sums[j] += *z[j].add(r) - shift[j];
                }
            }
        }
    };
}

#[cfg(target_arch = "x86_64")]
gram_kernel!(gram_avx2, "avx2,fma");

/// The same 3 × 3 tiles eight lanes wide in AVX-512's 32 registers: on cores with full-width
/// 512-bit FMA units (AMD Zen 5, Intel server cores) twice the products per cycle of the
/// AVX2 kernel; on Zen 4, which splits them in two, as fast. A panel's last rows are taken
/// with masked loads and shifts (the masked-off lanes are zero), so there is no scalar tail.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn gram_avx512(z: &[*const f64], n: usize, shift: &[f64], c: &mut [f64], sums: &mut [f64]) {
    use std::arch::x86_64::*;
    let m = z.len();
    // rows r..r1 as a lane mask (all eight but at a panel's end)
    let mask = |r: usize, r1: usize| -> __mmask8 {
        if r1 - r >= 8 {
            0xff
        } else {
            (1u8 << (r1 - r)) - 1
        }
    };
    let mut r0 = 0;
    while r0 < n {
        let r1 = (r0 + PANEL).min(n);
        let mut j0 = 0;
        while j0 < m {
            let mut i0 = j0;
            while i0 < m {
                if m - j0 >= 3 && m - i0 >= 3 {
                    let xi = [z[i0], z[i0 + 1], z[i0 + 2]];
                    let xj = [z[j0], z[j0 + 1], z[j0 + 2]];
                    let si = [
                        _mm512_set1_pd(shift[i0]),
                        _mm512_set1_pd(shift[i0 + 1]),
                        _mm512_set1_pd(shift[i0 + 2]),
                    ];
                    let sj = [
                        _mm512_set1_pd(shift[j0]),
                        _mm512_set1_pd(shift[j0 + 1]),
                        _mm512_set1_pd(shift[j0 + 2]),
                    ];
                    let load = |x: *const f64, s: __m512d, r: usize, k: __mmask8| {
                        _mm512_maskz_sub_pd(k, _mm512_maskz_loadu_pd(k, x.add(r)), s)
                    };
                    let full =
                        |x: *const f64, s: __m512d, r: usize| _mm512_sub_pd(_mm512_loadu_pd(x.add(r)), s);
                    let mut acc = [[_mm512_setzero_pd(); 3]; 3];
                    let mut r = r0;
                    if i0 == j0 {
                        let mut sum = [_mm512_setzero_pd(); 3];
                        while r < r1 {
                            let k = mask(r, r1);
                            let a = if k == 0xff {
                                [full(xi[0], si[0], r), full(xi[1], si[1], r), full(xi[2], si[2], r)]
                            } else {
                                [load(xi[0], si[0], r, k), load(xi[1], si[1], r, k), load(xi[2], si[2], r, k)]
                            };
                            for ai in 0..3 {
                                sum[ai] = _mm512_add_pd(sum[ai], a[ai]);
                                for bj in 0..3 {
                                    acc[ai][bj] = _mm512_fmadd_pd(a[ai], a[bj], acc[ai][bj]);
                                }
                            }
                            r += 8;
                        }
                        for (ai, v) in sum.iter().enumerate() {
                            sums[i0 + ai] += _mm512_reduce_add_pd(*v);
                        }
                    } else {
                        let whole = r0 + (r1 - r0) / 8 * 8;
                        while r < whole {
                            let a = [full(xi[0], si[0], r), full(xi[1], si[1], r), full(xi[2], si[2], r)];
                            for bj in 0..3 {
                                let b = full(xj[bj], sj[bj], r);
                                for ai in 0..3 {
                                    acc[ai][bj] = _mm512_fmadd_pd(a[ai], b, acc[ai][bj]);
                                }
                            }
                            r += 8;
                        }
                        if r < r1 {
                            let k = mask(r, r1);
                            let a = [
                                load(xi[0], si[0], r, k),
                                load(xi[1], si[1], r, k),
                                load(xi[2], si[2], r, k),
                            ];
                            for bj in 0..3 {
                                let b = load(xj[bj], sj[bj], r, k);
                                for ai in 0..3 {
                                    acc[ai][bj] = _mm512_fmadd_pd(a[ai], b, acc[ai][bj]);
                                }
                            }
                        }
                    }
                    for (ai, row) in acc.iter().enumerate() {
                        for (bj, v) in row.iter().enumerate() {
                            c[(i0 + ai) + (j0 + bj) * m] += _mm512_reduce_add_pd(*v);
                        }
                    }
                } else {
                    // edge tiles: one output at a time, still eight lanes wide
                    for a in i0..m.min(i0 + 3) {
                        for b in j0..m.min(j0 + 3) {
                            let (x, y) = (z[a], z[b]);
                            let (sx, sy) = (_mm512_set1_pd(shift[a]), _mm512_set1_pd(shift[b]));
                            let (mut acc, mut sum) = (_mm512_setzero_pd(), _mm512_setzero_pd());
                            let mut r = r0;
                            while r < r1 {
                                let k = mask(r, r1);
                                let dx = _mm512_maskz_sub_pd(k, _mm512_maskz_loadu_pd(k, x.add(r)), sx);
                                sum = _mm512_add_pd(sum, dx);
                                let dy = _mm512_maskz_sub_pd(k, _mm512_maskz_loadu_pd(k, y.add(r)), sy);
                                acc = _mm512_fmadd_pd(dx, dy, acc);
                                r += 8;
                            }
                            c[a + b * m] += _mm512_reduce_add_pd(acc);
                            if a == b {
                                sums[a] += _mm512_reduce_add_pd(sum);
                            }
                        }
                    }
                }
                i0 += 3;
            }
            j0 += 3;
        }
        r0 = r1;
    }
}

/// The portable kernel: lower triangle, four independent partial sums per output.
fn gram_tiles(z: &[&[f64]], n: usize, shift: &[f64], c: &mut [f64], sums: &mut [f64]) {
    let m = z.len();
    for j in 0..m {
        let (y, sy) = (&z[j][..n], shift[j]);
        let mut lanes = [0.0f64; LANES];
        let yc = y.chunks_exact(LANES);
        let tail: f64 = yc.remainder().iter().map(|b| b - sy).sum();
        for b in yc {
            for l in 0..LANES {
                lanes[l] += b[l] - sy;
            }
        }
        sums[j] += (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail;
        for i in j..m {
            let (x, sx) = (&z[i][..n], shift[i]);
            let mut lanes = [0.0f64; LANES];
            let (xc, yc) = (x.chunks_exact(LANES), y.chunks_exact(LANES));
            let (xr, yr) = (xc.remainder(), yc.remainder());
            for (a, b) in xc.zip(yc) {
                for l in 0..LANES {
                    lanes[l] += (a[l] - sx) * (b[l] - sy);
                }
            }
            let mut s = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
            for (a, b) in xr.iter().zip(yr) {
                s += (a - sx) * (b - sy);
            }
            c[i + j * m] += s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equals_naive_product_for_awkward_sizes() {
        for (n, m, ld) in [(1, 1, 1), (7, 5, 9), (33, 13, 40), (100, 31, 100), (600, 30, 601)] {
            let z: Vec<f64> =
                (0..ld * m).map(|i| ((i * 37) % 17) as f64 - 8.0 + 0.25 * (i % 3) as f64).collect();
            let shift: Vec<f64> = (0..m).map(|j| j as f64 * 0.5 - 3.0).collect();
            let columns: Vec<&[f64]> = (0..m).map(|j| &z[j * ld..j * ld + n]).collect();
            let (mut c, mut sums) = (vec![0.0; m * m], vec![0.0; m]);
            gram_add(&columns, &shift, &mut c, &mut sums);
            mirror(&mut c, m);
            let (mut p, mut psums) = (vec![0.0; m * m], vec![0.0; m]);
            gram_tiles(&columns, n, &shift, &mut p, &mut psums);
            mirror(&mut p, m);
            for i in 0..m {
                let want: f64 = (0..n).map(|r| z[i * ld + r] - shift[i]).sum();
                assert!((sums[i] - want).abs() <= 1e-12 * want.abs().max(1.0), "{n}×{m} sum {i}");
                assert!((psums[i] - want).abs() <= 1e-12 * want.abs().max(1.0));
            }
            // the AVX2 kernel too, which this machine may not dispatch to
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
                let ptrs: Vec<*const f64> = columns.iter().map(|z| z.as_ptr()).collect();
                let (mut a, mut asums) = (vec![0.0; m * m], vec![0.0; m]);
                // SAFETY: features checked; pointers to columns of n values
                unsafe { gram_avx2(&ptrs, n, &shift, &mut a, &mut asums) };
                mirror(&mut a, m);
                for (x, y) in a.iter().chain(&asums).zip(c.iter().chain(&sums)) {
                    assert!((x - y).abs() <= 1e-12 * y.abs().max(1.0), "avx2 {n}×{m}");
                }
            }
            let mut plain = vec![f64::NAN; m * m];
            gram(&z, ld, n, m, &mut plain);
            for i in 0..m {
                for j in 0..m {
                    let want: f64 =
                        (0..n).map(|r| (z[i * ld + r] - shift[i]) * (z[j * ld + r] - shift[j])).sum();
                    let tol = 1e-12 * want.abs().max(1.0);
                    assert!((c[i + j * m] - want).abs() <= tol, "{n}×{m} ({i},{j})");
                    assert!((p[i + j * m] - want).abs() <= tol);
                    let unshifted: f64 = (0..n).map(|r| z[i * ld + r] * z[j * ld + r]).sum();
                    assert!((plain[i + j * m] - unshifted).abs() <= 1e-12 * unshifted.abs().max(1.0));
                }
            }
        }
    }
}
