//! termid as a library, no ship in sight: simulate the Lorenz system from its model file,
//! forget its coefficients, identify them back from the trajectory (central differences for
//! the derivatives, each equation's back-end from the file), and simulate the identified model
//! beside the truth. The same calls `termid simulate` and `termid identify --model … --out …`
//! make.
//!
//! `cargo run --release --example lorenz`

use std::collections::BTreeMap;
use std::path::Path;

use termid::data::{CentralDifference, Frame};
use termid::identify::{identify_model, ModelIdentification};
use termid::model::Model;
use termid::sim::{simulate, Constant, Integrator, Settings, System};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let truth = Model::load(Path::new("models/lorenz.toml"))?;
    let settings = Settings { integrator: Integrator::Rk4, dt: 0.001, duration: 10.0, sample: 0.002 };
    let x0 = [-8.0, 7.0, 27.0];
    let run =
        simulate(&System::new(&truth, &BTreeMap::new(), false)?, &x0, &mut Constant(vec![]), &settings)?;
    // only the states, as a measurement would have them: the derivatives come from the data
    let mut frame = Frame::new("lorenz run", "t", run.time.clone())?;
    for (name, column) in run.state_names.iter().zip(&run.states) {
        frame.push(name, column.clone())?;
    }
    println!("simulated {} samples of the Lorenz system ({} s)", frame.len(), settings.duration);

    let how = ModelIdentification {
        equations: vec![],
        differentiator: &CentralDifference,
        intercept: false,
        target: None,
    };
    let identified = identify_model(&truth, &[frame], &how, &mut |eq| eprintln!("identifying {eq} …"))?;
    for (name, fit) in &identified.fits {
        println!("\n{name}:\n{}", fit.text());
    }

    // the identified model predicts the chaotic trajectory for a while (a Lyapunov time is
    // ~1.1 s, and central differences leave an O(h²) error in every coefficient)
    let again = simulate(
        &System::new(&identified.model, &BTreeMap::new(), false)?,
        &x0,
        &mut Constant(vec![]),
        &Settings { duration: 2.0, ..settings },
    )?;
    let k = again.time.len() - 1;
    println!("after 2 s: truth x = {:.4}, identified x = {:.4}", run.states[0][k], again.states[0][k]);
    Ok(())
}
