//! fitbead in ten steps: one scene forward, K of one measured point, then the law
//! K = cos 2α + c sin²α sin 2α fitted to a data set by least squares and by MCMC.
use fitbead::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // ξ = r/R = 1, slope δ = 12°, sphere (ρ = 0.4), friction f = 0.1, the paper's fitted K law.
    let scene = Scene::builder()
        .xi(1.0)
        .delta_deg(12.0)
        .rho(0.4)
        .friction(0.1)
        .law(CollisionLaw::Adjusted)
        .build()?;
    let steady = Model::Stick.evaluate(&scene)?;
    println!("stick model: mean velocity v = {}", steady.mean_velocity);

    // Eq 69: the K that makes the stick model roll at the measured v = 0.35 ± 0.01.
    let k = estimate_k(&Model::Stick, &scene, 0.35, Some(0.01));
    println!(
        "K = {} (K at v - sigma: {:?}, at v + sigma: {:?})",
        k.k()?,
        k.k_lo,
        k.k_hi
    );

    // Measurements: series,xi,delta_deg,v,sigma_v (v in units of sqrt(g (R + r))).
    let data = Dataset::from_csv("data/default.csv")?;

    // Law c under the stick/slip model, by least squares: the fit report.
    let lsq = KLawFitter::new(Model::StickSlip, KLaw::C).fit(&data)?;
    println!("{lsq}");

    // The same law by MCMC (seed 1: the same draws on any machine and thread count).
    let mcmc = KLawFitter::new(Model::StickSlip, KLaw::C)
        .mcmc(McmcSettings::seeded(1))
        .fit(&data)?;
    println!("posterior median c = {}", mcmc.param("c")?.value);

    let c = lsq.param("c")?;
    println!("c = {} ± {}", c.value, c.stderr.unwrap_or(f64::NAN));
    Ok(())
}
