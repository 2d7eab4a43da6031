//! The ship plug-in's hypotheses for `termid diagnose`: the generic library with the names a
//! naval architect uses, and effects made of several terms (Oltmann's B0·u², C0·u²).

use crate::diagnose::{generic_hypotheses, Effect, Hypothesis};
use crate::model::Model;

/// The generic library, renamed where a ship name exists, plus the ship's own.
pub fn hypotheses(model: &Model) -> Vec<Hypothesis> {
    let rudder = super::canonical_spec(model).map(|s| s.names.rudder);
    let mut out: Vec<Hypothesis> = generic_hypotheses(model)
        .into_iter()
        .map(|mut h| {
            let name = match &h.effect {
                Effect::InputOffset { input } if Some(input) == rudder.as_ref() => {
                    Some("rudder zero offset".to_string())
                }
                Effect::InputScale { input } if Some(input) == rudder.as_ref() => {
                    Some("rudder angle scale error".to_string())
                }
                Effect::Terms { terms } if terms.len() == 1 && terms[0].1 == "u^2" => {
                    Some(match terms[0].0.as_str() {
                        "v_dot" => "propeller-induced side force B0·u² (sway asymmetry)".to_string(),
                        "r_dot" => "propeller-induced yaw moment C0·u² (yaw asymmetry)".to_string(),
                        other => format!("asymmetry u² in {other}"),
                    })
                }
                _ => None,
            };
            if let Some(n) = name {
                h.name = n;
            }
            h
        })
        .collect();
    let has = |eq: &str| model.equation(eq).is_some_and(|e| e.identify);
    if has("v_dot") && has("r_dot") {
        out.push(Hypothesis {
            name: "propeller-induced asymmetry B0·u², C0·u²".into(),
            effect: Effect::Terms {
                terms: vec![("v_dot".into(), "u^2".into()), ("r_dot".into(), "u^2".into())],
            },
        });
        out.push(Hypothesis {
            name: "speed dependence of the rudder force (u·Δu·δ in v̇ and ṙ)".into(),
            effect: Effect::Terms {
                terms: vec![("v_dot".into(), "u*Δu*δ".into()), ("r_dot".into(), "u*Δu*δ".into())],
            },
        });
    }
    // the generic single u² hypotheses use the candidate's canonical text
    out.retain(|h| !matches!(&h.effect, Effect::Terms { terms } if terms.iter().any(|t| t.1 == "Δu*u^2")));
    out
}
