//! Effective samples per second of the K(α) posterior (law c, stick/slip model, 40 points made
//! as in `tests/it/fits.rs`), on one core: a rayon pool of one thread runs the whole command's
//! work — the least-squares start, the sampler to its stopping rule (bulk and tail ESS ≥ 1000,
//! R̂ ≤ 1.01, run ≥ 50 τ) and the diagnostics.
//!
//! Before timing, one run prints its smallest ESS, steps, walkers and log-density evaluations
//! (deterministic for the seed), from which ESS/s = ESS / median time and evaluations per
//! effective sample follow: `cargo bench --features bench-internals --bench mcmc`.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fitbead::fit::builder::KLawFitter;
use fitbead::fit::klaw::KLaw;
use fitbead::inverse::mcmc::McmcOptions;
use fitbead::inverse::posterior::McmcSettings;
use fitbead::{CollisionLaw, Model};

#[allow(dead_code, unused_imports)]
#[path = "../tests/it/fits.rs"]
mod fits;

fn bench(c: &mut Criterion) {
    let law = CollisionLaw::Adjusted;
    let data = fits::simulate(
        |_, _| Model::StickSlip,
        fits::regime_b(law),
        law,
        10,
        0.02,
        7,
    );
    let fitter = KLawFitter::new(Model::StickSlip, KLaw::C).mcmc(McmcSettings {
        options: McmcOptions {
            seed: 1,
            ..Default::default()
        },
        ..Default::default()
    });
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let run = || pool.install(|| fitter.fit(black_box(&data))).unwrap();
    let once = run();
    let s = &once.stats;
    let m = s.mcmc.as_ref().unwrap();
    let evals = m.walkers * m.steps;
    eprintln!(
        "klaw stickslip c, 40 points, one core: status {}, min ESS {:.0}, {} steps x {} walkers \
         = {} log-density evaluations ({:.2} per effective sample), acceptance {:.2}",
        m.status,
        m.ess_min,
        m.steps,
        m.walkers,
        evals,
        evals as f64 / m.ess_min,
        m.acceptance
    );
    let mut g = c.benchmark_group("mcmc");
    g.sample_size(10);
    g.bench_function(
        "klaw stickslip c, 40 points, one core, to convergence",
        |b| b.iter(run),
    );
    g.finish();
}

/// The autocovariance of one chain (what every convergence check computes per parameter):
/// fitbead's (`realfft`, plans cached per thread), `realfft` planned on every call, a
/// hand-written iterative radix-2 complex FFT (bit reversal, direct twiddle table), and the
/// direct O(n²) sum, on AR(1) chains of 10⁴ and 10⁵ steps. The four agree to 1e-12 of γ(0).
fn autocovariance(c: &mut Criterion) {
    use fitbead::bench_internals::autocovariance as ours;
    use realfft::RealFftPlanner;
    fn chain(n: usize) -> Vec<f64> {
        let mut x = vec![0.0; n];
        let mut s: u64 = 1;
        for i in 1..n {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            x[i] = 0.9 * x[i - 1] + u;
        }
        x
    }
    fn centred(x: &[f64], m: usize) -> Vec<f64> {
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let mut v = vec![0.0; m];
        for (r, &e) in v.iter_mut().zip(x) {
            *r = e - mean;
        }
        v
    }
    fn by_realfft(x: &[f64]) -> Vec<f64> {
        let n = x.len();
        let m = (2 * n).next_power_of_two();
        let mut planner = RealFftPlanner::<f64>::new();
        let (r2c, c2r) = (planner.plan_fft_forward(m), planner.plan_fft_inverse(m));
        let mut input = centred(x, m);
        let mut spectrum = r2c.make_output_vec();
        r2c.process(&mut input, &mut spectrum).unwrap();
        for z in spectrum.iter_mut() {
            *z = realfft::num_complex::Complex::new(z.norm_sqr(), 0.0);
        }
        let mut out = c2r.make_output_vec();
        c2r.process(&mut spectrum, &mut out).unwrap();
        out.truncate(n);
        out.iter_mut().for_each(|v| *v /= (m * n) as f64);
        out
    }
    fn fft(re: &mut [f64], im: &mut [f64], inverse: bool) {
        let n = re.len();
        let mut j = 0usize;
        for i in 1..n {
            let mut bit = n >> 1;
            while j & bit != 0 {
                j ^= bit;
                bit >>= 1;
            }
            j |= bit;
            if i < j {
                re.swap(i, j);
                im.swap(i, j);
            }
        }
        let sign = if inverse { 1.0 } else { -1.0 };
        let theta = sign * 2.0 * std::f64::consts::PI / n as f64;
        let tw: Vec<(f64, f64)> = (0..n / 2).map(|k| (theta * k as f64).sin_cos()).collect();
        let mut len = 2;
        while len <= n {
            let (half, stride) = (len / 2, n / len);
            for start in (0..n).step_by(len) {
                for k in 0..half {
                    let (s, c) = tw[k * stride];
                    let (a, b) = (start + k, start + k + half);
                    let tr = re[b] * c - im[b] * s;
                    let ti = re[b] * s + im[b] * c;
                    re[b] = re[a] - tr;
                    im[b] = im[a] - ti;
                    re[a] += tr;
                    im[a] += ti;
                }
            }
            len <<= 1;
        }
    }
    fn by_radix2(x: &[f64]) -> Vec<f64> {
        let n = x.len();
        let m = (2 * n).next_power_of_two();
        let mut re = centred(x, m);
        let mut im = vec![0.0; m];
        fft(&mut re, &mut im, false);
        for (r, i) in re.iter_mut().zip(im.iter_mut()) {
            *r = *r * *r + *i * *i;
            *i = 0.0;
        }
        fft(&mut re, &mut im, true);
        re.truncate(n);
        re.iter_mut().for_each(|v| *v /= (m * n) as f64);
        re
    }
    fn direct(x: &[f64]) -> Vec<f64> {
        let n = x.len();
        let v = centred(x, n);
        (0..n)
            .map(|t| (0..n - t).map(|i| v[i] * v[i + t]).sum::<f64>() / n as f64)
            .collect()
    }
    let mut g = c.benchmark_group("autocovariance");
    g.sample_size(20);
    for n in [10_000, 100_000] {
        let x = chain(n);
        let a = ours(&x);
        let mut others = vec![by_realfft(&x), by_radix2(&x)];
        if n <= 10_000 {
            others.push(direct(&x));
        }
        for b in &others {
            let worst = a
                .iter()
                .zip(b)
                .map(|(u, v)| (u - v).abs())
                .fold(0.0, f64::max)
                / a[0];
            assert!(worst < 1e-12, "autocovariances differ by {worst:e} of γ(0)");
        }
        g.bench_function(format!("fitbead (realfft, cached plans), n = {n}"), |bn| {
            bn.iter(|| ours(black_box(&x)))
        });
        g.bench_function(format!("realfft planned per call, n = {n}"), |bn| {
            bn.iter(|| by_realfft(black_box(&x)))
        });
        g.bench_function(format!("radix-2 complex FFT, n = {n}"), |bn| {
            bn.iter(|| by_radix2(black_box(&x)))
        });
        if n <= 10_000 {
            g.bench_function(format!("direct sum, n = {n}"), |bn| {
                bn.iter(|| direct(black_box(&x)))
            });
        }
    }
    g.finish();
}

/// One convergence check of one parameter (R̂, bulk and tail ESS; what a check during a
/// one-parameter run computes, with no other work for the threads): 32 AR(1) chains of 4,000
/// steps, on rayon pools of one and two threads. Its three parts and the rank transform run
/// side by side; the result is the same on either pool.
fn convergence(c: &mut Criterion) {
    use fitbead::bench_internals::convergence as check;
    let chains: Vec<Vec<f64>> = (0..32u64)
        .map(|w| {
            let mut x = vec![0.0; 4000];
            let mut s = 0x9e37_79b9_7f4a_7c15u64.wrapping_mul(w + 1);
            for i in 1..x.len() {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                let u = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                x[i] = 0.9 * x[i - 1] + u;
            }
            x
        })
        .collect();
    let mut g = c.benchmark_group("convergence check");
    g.sample_size(20);
    let mut seen = Vec::new();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        seen.push(pool.install(|| check(&chains)));
        g.bench_function(
            format!("32 chains x 4000 steps, {threads} thread(s)"),
            |b| b.iter(|| pool.install(|| check(black_box(&chains)))),
        );
    }
    let bits = |r: &(f64, f64, f64)| [r.0.to_bits(), r.1.to_bits(), r.2.to_bits()];
    assert_eq!(bits(&seen[0]), bits(&seen[1]), "1 and 2 threads differ");
    g.finish();
}

criterion_group!(benches, bench, autocovariance, convergence);
criterion_main!(benches);
