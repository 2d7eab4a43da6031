//! `termid scale`: a model rescaled by Froude's law, its plug-in's table included.

use anyhow::{bail, Result};

use crate::args::ScaleCommand;

pub fn run(cmd: ScaleCommand) -> Result<()> {
    // beyond these, masses (× λ³) and the coefficients' powers of λ leave the numbers a
    // model file can hold; no ship and no model differ by more than 10⁴ in length
    if !(cmd.factor.is_finite() && (1e-4..=1e4).contains(&cmd.factor)) {
        bail!(
            "--factor {}: a length factor is a positive number from 1e-4 to 1e4 (new length / old length)",
            cmd.factor
        );
    }
    termid::output::check_file(&cmd.out)?;
    crate::runs::check_outputs(&[("--out", &cmd.out)], &[("--model".into(), cmd.model.clone())])?;
    let model = termid::plugins::load(&cmd.model)?;
    let (length, time, mass) = (cmd.factor, cmd.factor.sqrt(), cmd.factor.powi(3));
    let mut scaled = termid::plugins::rescaled(&model, length, time, mass)?;
    scaled.add_note(format!(
        "rescaled by Froude's law from {} (lengths × {length}, times × {time:.6}, masses × {mass:.6e})",
        cmd.model.display()
    ));
    termid::output::write_file(&cmd.out, scaled.to_toml().as_bytes())?;
    println!(
        "wrote {}: lengths × {length}, speeds and times × {time:.6}, masses × {mass:.6e}",
        cmd.out.display()
    );
    Ok(())
}
