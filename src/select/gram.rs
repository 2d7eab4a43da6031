//! (Z − 1cᵀ)ᵀ(Z − 1cᵀ) for a tall, narrow block of columns Z shifted by a constant per column:
//! the cross-products of the shifted-data algorithm ([`super::Accumulator`]). The columns are
//! read where they are (the term evaluator's output, a user's matrix) and shifted in registers,
//! not copied first (the copy had cost ~6 % of a 2 505-row fit). Only the lower triangle is
//! computed (half the flops of a general product, as BLAS dsyrk); [`mirror`] completes it where
//! a full matrix is wanted. On x86-64 register-tiled kernels with explicit intrinsics
//! (AVX-512, else AVX2+FMA, checked at run time); elsewhere a portable one.

const LANES: usize = 4;

/// C (m × m, column-major) = ZᵀZ for Z of `n` rows, `m` columns, leading dimension `ld`.
pub fn gram(z: &[f64], ld: usize, n: usize, m: usize, c: &mut [f64]) {
    assert!(n <= ld && z.len() >= ld * (m.max(1) - 1) + n && c.len() == m * m, "gram: buffer sizes");
    let columns: Vec<&[f64]> = (0..m).map(|j| &z[j * ld..j * ld + n]).collect();
    c.fill(0.0);
    gram_add(&columns, &vec![0.0; m], c, &mut vec![0.0; m]);
    mirror(c, m);
}

/// Adds Σ_r (z_i\[r\] − c_i)(z_j\[r\] − c_j) to `c[i + j m]` for i ≥ j (and to the upper entries
/// of the diagonal 3 × 3 tiles, which [`mirror`] overwrites), and Σ_r (z_i\[r\] − c_i) to
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

/// The x86-64 kernels: one tile loop, written once in [`tile_kernel`] over the vector
/// operations each kernel defines, instantiated for AVX2's four lanes and AVX-512's eight.
/// (A generic function over a trait of vector operations was tried: its intrinsics were not
/// inlined into the feature-enabled kernels, 50× slower.)
///
/// 3 × 3 output tiles: 9 accumulators and the 6 loaded columns, and the six broadcast shifts
/// where there is room (AVX-512's 32 registers; with AVX2's 16 they are re-read from L1, which
/// the load ports absorb). The shift subtractions and the diagonal tiles' column sums
/// run on the FP add ports, so the FMAs stay the bottleneck. A panel's last rows are taken as a
/// partial vector (lanes beyond them zero), so there is no scalar tail.
#[cfg(target_arch = "x86_64")]
macro_rules! tile_kernel {
    ($z:ident, $n:ident, $shift:ident, $c:ident, $sums:ident, lanes: $lanes:expr,
     splat: $splat:expr, zero: $zero:expr, shifted: $shifted:expr, part: $part:expr,
     add: $add:expr, fmadd: $fmadd:expr, sum: $sum:expr) => {{
        let (z, n, shift, c, sums) = ($z, $n, $shift, $c, $sums);
        let (splat, zero, shifted, part, add, fmadd, sum) =
            ($splat, $zero, $shifted, $part, $add, $fmadd, $sum);
        let m = z.len();
        let mut r0 = 0;
        while r0 < n {
            let r1 = (r0 + PANEL).min(n);
            let whole = r0 + (r1 - r0) / $lanes * $lanes;
            // x[r..] − s as a vector: whole, or the panel's last rows
            let load = |x: *const f64, s, r: usize| {
                if r < whole {
                    shifted(x.add(r), s)
                } else {
                    part(x.add(r), s, r1 - r)
                }
            };
            let mut j0 = 0;
            while j0 < m {
                let mut i0 = j0;
                while i0 < m {
                    if m - j0 >= 3 && m - i0 >= 3 {
                        let xi = [z[i0], z[i0 + 1], z[i0 + 2]];
                        let xj = [z[j0], z[j0 + 1], z[j0 + 2]];
                        let si = [splat(shift[i0]), splat(shift[i0 + 1]), splat(shift[i0 + 2])];
                        let sj = [splat(shift[j0]), splat(shift[j0 + 1]), splat(shift[j0 + 2])];
                        let mut acc = [[zero(); 3]; 3];
                        let mut r = r0;
                        if i0 == j0 {
                            let mut s3 = [zero(); 3];
                            let mut products = |a: [_; 3]| {
                                for ai in 0..3 {
                                    s3[ai] = add(s3[ai], a[ai]);
                                    for bj in 0..3 {
                                        acc[ai][bj] = fmadd(a[ai], a[bj], acc[ai][bj]);
                                    }
                                }
                            };
                            while r < whole {
                                products([
                                    shifted(xi[0].add(r), si[0]),
                                    shifted(xi[1].add(r), si[1]),
                                    shifted(xi[2].add(r), si[2]),
                                ]);
                                r += $lanes;
                            }
                            if r < r1 {
                                products([
                                    load(xi[0], si[0], r),
                                    load(xi[1], si[1], r),
                                    load(xi[2], si[2], r),
                                ]);
                            }
                            for (ai, v) in s3.iter().enumerate() {
                                sums[i0 + ai] += sum(*v);
                            }
                        } else {
                            let mut products = |a: [_; 3], b: [_; 3]| {
                                for bj in 0..3 {
                                    for ai in 0..3 {
                                        acc[ai][bj] = fmadd(a[ai], b[bj], acc[ai][bj]);
                                    }
                                }
                            };
                            while r < whole {
                                let column = |x: *const f64, s| shifted(x.add(r), s);
                                products(
                                    [column(xi[0], si[0]), column(xi[1], si[1]), column(xi[2], si[2])],
                                    [column(xj[0], sj[0]), column(xj[1], sj[1]), column(xj[2], sj[2])],
                                );
                                r += $lanes;
                            }
                            if r < r1 {
                                products(
                                    [load(xi[0], si[0], r), load(xi[1], si[1], r), load(xi[2], si[2], r)],
                                    [load(xj[0], sj[0], r), load(xj[1], sj[1], r), load(xj[2], sj[2], r)],
                                );
                            }
                        }
                        for (ai, row) in acc.iter().enumerate() {
                            for (bj, v) in row.iter().enumerate() {
                                c[(i0 + ai) + (j0 + bj) * m] += sum(*v);
                            }
                        }
                    } else {
                        // edge tiles: one output at a time, still a vector wide
                        for a in i0..m.min(i0 + 3) {
                            for b in j0..m.min(j0 + 3) {
                                let (sx, sy) = (splat(shift[a]), splat(shift[b]));
                                let (mut acc, mut s1) = (zero(), zero());
                                let mut r = r0;
                                while r < r1 {
                                    let (dx, dy) = (load(z[a], sx, r), load(z[b], sy, r));
                                    s1 = add(s1, dx);
                                    acc = fmadd(dx, dy, acc);
                                    r += $lanes;
                                }
                                c[a + b * m] += sum(acc);
                                if a == b {
                                    sums[a] += sum(s1);
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
    }};
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn gram_avx2(z: &[*const f64], n: usize, shift: &[f64], c: &mut [f64], sums: &mut [f64]) {
    use std::arch::x86_64::*;
    tile_kernel!(z, n, shift, c, sums, lanes: 4,
    splat: |x: f64| _mm256_set1_pd(x),
    zero: || _mm256_setzero_pd(),
    shifted: |x: *const f64, s: __m256d| _mm256_sub_pd(_mm256_loadu_pd(x), s),
    part: |x: *const f64, s: __m256d, left: usize| {
        let on = _mm256_cmpgt_epi64(_mm256_set1_epi64x(left as i64), _mm256_setr_epi64x(0, 1, 2, 3));
        _mm256_and_pd(_mm256_sub_pd(_mm256_maskload_pd(x, on), s), _mm256_castsi256_pd(on))
    },
    add: |a: __m256d, b: __m256d| _mm256_add_pd(a, b),
    fmadd: |a: __m256d, b: __m256d, acc: __m256d| _mm256_fmadd_pd(a, b, acc),
    sum: |v: __m256d| {
        let mut lanes = [0.0f64; 4];
        _mm256_storeu_pd(lanes.as_mut_ptr(), v);
        (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
    })
}

/// On cores with full-width 512-bit FMA units (AMD Zen 5, Intel server cores) twice the
/// products per cycle of AVX2; on Zen 4, which splits them in two, as fast.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn gram_avx512(z: &[*const f64], n: usize, shift: &[f64], c: &mut [f64], sums: &mut [f64]) {
    use std::arch::x86_64::*;
    tile_kernel!(z, n, shift, c, sums, lanes: 8,
    splat: |x: f64| _mm512_set1_pd(x),
    zero: || _mm512_setzero_pd(),
    shifted: |x: *const f64, s: __m512d| _mm512_sub_pd(_mm512_loadu_pd(x), s),
    part: |x: *const f64, s: __m512d, left: usize| {
        let on: __mmask8 = (1u8 << left) - 1;
        _mm512_maskz_sub_pd(on, _mm512_maskz_loadu_pd(on, x), s)
    },
    add: |a: __m512d, b: __m512d| _mm512_add_pd(a, b),
    fmadd: |a: __m512d, b: __m512d, acc: __m512d| _mm512_fmadd_pd(a, b, acc),
    // halves added, then as AVX2's sum: a fixed order (`_mm512_reduce_add_pd` is an
    // unordered reduction, whose rounding changed with a column's place in its tile and so
    // with the order of the candidates)
    sum: |v: __m512d| {
        let half = _mm256_add_pd(_mm512_castpd512_pd256(v), _mm512_extractf64x4_pd::<1>(v));
        let mut lanes = [0.0f64; 4];
        _mm256_storeu_pd(lanes.as_mut_ptr(), half);
        (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
    })
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
