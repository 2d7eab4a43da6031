//! Starting values for a ship nobody has tested: the MMG model's hull derivatives, masses,
//! propeller and rudder parameters estimated from the main particulars by published
//! semi-empirical formulas (each cited where it is used), written as a grey-box model file
//! whose parameters are free with those estimates as priors (`termid new-ship`, then
//! `termid estimate` on the ship's runs).

use serde::{Deserialize, Serialize};

use crate::model::{Model, ModelError, PriorSpec};

/// A ship's main particulars (SI, angles in degrees), as a particulars file gives them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Particulars {
    /// The ship's name.
    pub name: String,
    /// Length between perpendiculars L, m.
    pub lpp: f64,
    /// Beam B, m.
    pub beam: f64,
    /// Draught d, m (mean).
    pub draught: f64,
    /// Block coefficient C_B.
    pub block_coefficient: f64,
    /// Longitudinal centre of gravity from midship, forward positive, m.
    #[serde(default)]
    pub x_g: f64,
    /// Movable rudder area A_R, m².
    pub rudder_area: f64,
    /// Rudder span (height) H_R, m.
    pub rudder_span: f64,
    /// Propeller diameter D_p, m.
    pub propeller_diameter: f64,
    /// The propeller's open-water thrust coefficient K_T(J) = k0 + k1·J + k2·J² (default: a
    /// single-screw tanker's propeller, KVLCC2's; give the ship's own where known).
    #[serde(default = "tanker_propeller")]
    pub kt: [f64; 3],
    /// Approach speed u0, m/s.
    pub u0: f64,
    /// Rudder rate, °/s.
    pub rudder_rate: f64,
    /// Largest rudder angle, °.
    #[serde(default = "thirty_five")]
    pub rudder_limit: f64,
    /// Water density, kg/m³.
    #[serde(default = "sea_water")]
    pub density: f64,
}

fn tanker_propeller() -> [f64; 3] {
    [0.2931, -0.2753, -0.1385]
}

fn thirty_five() -> f64 {
    35.0
}

fn sea_water() -> f64 {
    1025.0
}

/// One estimated parameter of the MMG model: its value, the prior's standard deviation, and
/// where the value comes from.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// The model file's parameter.
    pub name: &'static str,
    /// The estimate.
    pub value: f64,
    /// The prior's standard deviation (0: a fixed quantity, not free).
    pub sd: f64,
    /// Its unit.
    pub unit: &'static str,
    /// The formula's source.
    pub source: &'static str,
}

/// Why particulars cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ParticularsError {
    /// A value out of its range.
    #[error("particulars: `{key}` = {value}: {why}")]
    Value {
        /// The key.
        key: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        why: &'static str,
    },
    /// The template could not take the estimates.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The particulars' text is not a particulars file (its key and line in `message`).
    #[error("{file}: {message}")]
    Syntax {
        /// The file (or what stands for it).
        file: String,
        /// What is wrong, where.
        message: String,
    },
}

const KIJIMA: &str = "Kijima, Katsuno, Nakiri & Furukawa (1990), J. Soc. Nav. Arch. Japan 168";
const CLARKE: &str = "Clarke, Gedling & Hine (1983), Trans. RINA 125 (read 1982)";
const FUJII: &str = "Fujii & Tsuda (1961), via Yasukawa & Yoshimura (2015) eq. (26)";
const TAYLOR: &str = "Taylor's single-screw wake fraction w = 0.5·C_B − 0.05";
const GEOMETRY: &str = "the particulars";
const GENERIC: &str = "no formula from particulars: a generic full-form single-screw value, wide prior";

impl Particulars {
    /// Reads a particulars file's TOML `text`; `file` names it in messages.
    pub fn parse(text: &str, file: &str) -> Result<Particulars, ParticularsError> {
        toml::from_str(text).map_err(|e| ParticularsError::Syntax {
            file: file.into(),
            message: crate::contain::toml_message(&e, text),
        })
    }

    /// Refuses particulars a ship cannot have.
    pub fn check(&self) -> Result<(), ParticularsError> {
        let positive = [
            ("lpp", self.lpp),
            ("beam", self.beam),
            ("draught", self.draught),
            ("rudder_area", self.rudder_area),
            ("rudder_span", self.rudder_span),
            ("propeller_diameter", self.propeller_diameter),
            ("u0", self.u0),
            ("rudder_rate", self.rudder_rate),
            ("rudder_limit", self.rudder_limit),
            ("density", self.density),
        ];
        for (key, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(ParticularsError::Value { key, value, why: "must be a number > 0" });
            }
        }
        if let Some(k) = self.kt.iter().find(|k| !k.is_finite()) {
            return Err(ParticularsError::Value {
                key: "kt",
                value: *k,
                why: "K_T(J)'s coefficients must be numbers",
            });
        }
        if !(self.kt[0] > 0.0 && self.kt[0] < 1.0) {
            return Err(ParticularsError::Value {
                key: "kt",
                value: self.kt[0],
                why: "the propeller's K_T at J = 0 (kt's first) lies between 0 and 1 (0.2-0.5 is usual)",
            });
        }
        if !(0.3..=1.0).contains(&self.block_coefficient) {
            return Err(ParticularsError::Value {
                key: "block_coefficient",
                value: self.block_coefficient,
                why: "a ship's C_B lies between 0.3 and 1",
            });
        }
        if self.propeller_diameter > self.rudder_span * 1.5 || self.rudder_span > self.draught * 1.5 {
            return Err(ParticularsError::Value {
                key: "rudder_span",
                value: self.rudder_span,
                why: "the rudder spans about the propeller's diameter and less than the draught",
            });
        }
        // proportions no displacement ship has: a value in other units (cm, feet) or a key
        // mistaken for another, which the formulas would turn into a model without complaint
        let (l_b, b_d) = (self.lpp / self.beam, self.beam / self.draught);
        if !(2.0..=15.0).contains(&l_b) {
            return Err(ParticularsError::Value {
                key: "beam",
                value: self.beam,
                why: "L/B outside 2-15, no displacement ship's: are lpp and beam in metres?",
            });
        }
        if !(1.0..=10.0).contains(&b_d) {
            return Err(ParticularsError::Value {
                key: "draught",
                value: self.draught,
                why: "B/d outside 1-10, no displacement ship's: are beam and draught in metres?",
            });
        }
        if self.x_g.abs() >= 0.5 * self.lpp || !self.x_g.is_finite() {
            return Err(ParticularsError::Value {
                key: "x_g",
                value: self.x_g,
                why: "the centre of gravity lies within the ship, |x_g| < L/2 (from midship, m)",
            });
        }
        // the steering gear as a ship's model file may have it
        use super::spec::{RUDDER_LIMIT, RUDDER_RATE};
        for (key, value, (range, why)) in [
            ("rudder_limit", self.rudder_limit, RUDDER_LIMIT),
            ("rudder_rate", self.rudder_rate, RUDDER_RATE),
        ] {
            if !range.contains(&value) {
                return Err(ParticularsError::Value { key, value, why });
            }
        }
        Ok(())
    }

    /// Where the particulars lie outside a usual merchant hull's proportions (L/B 4-9, B/d
    /// 1.8-5, C_B 0.5-0.9): the hull formulas are regressions over merchant hulls, so their
    /// estimates there are extrapolations, less sure than the priors' standard deviations say.
    /// Empty where every proportion is usual.
    pub fn cautions(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (what, value, (lo, hi)) in [
            ("L/B", self.lpp / self.beam, (4.0, 9.0)),
            ("B/d", self.beam / self.draught, (1.8, 5.0)),
            ("C_B", self.block_coefficient, (0.5, 0.9)),
        ] {
            if !(lo..=hi).contains(&value) {
                out.push(format!(
                    "{what} = {value:.3} lies outside {lo}-{hi}, a usual merchant hull's: the hull formulas (Kijima, Clarke) are regressions over merchant hulls and extrapolate here; let the runs decide (`termid estimate`) and compare the result with the priors"
                ));
            }
        }
        out
    }

    /// Every parameter of the MMG model estimated from the particulars, the hull's
    /// derivatives nondimensional as the MMG standard method writes them (forces by ½ρLdU²,
    /// moments by ½ρL²dU², v' = v/U, r' = rL/U).
    pub fn estimates(&self) -> Vec<Estimate> {
        let (l, b, d, cb, rho) = (self.lpp, self.beam, self.draught, self.block_coefficient, self.density);
        let volume = cb * l * b * d;
        let m = rho * volume;
        // masses in ½ρL²d (forces) and ½ρL⁴d (moments) units
        let force_unit = 0.5 * rho * l * l * d;
        let m_prime = m / force_unit;
        let k = 2.0 * d / l;
        let cbl = cb * b / l;
        // Clarke et al. (1983) added masses, in ½ρL³ and ½ρL⁵
        let slender = std::f64::consts::PI * (d / l).powi(2);
        let m_y = slender * (1.0 + 0.16 * cb * b / d - 5.1 * (b / l).powi(2)) * 0.5 * rho * l.powi(3);
        let j_z = slender * (1.0 / 12.0 + 0.017 * cb * b / d - 0.33 * b / l) * 0.5 * rho * l.powi(5);
        let m_x = 0.05 * m;
        let m_x_prime = m_x / force_unit;
        let lambda = self.rudder_span.powi(2) / self.rudder_area;
        let w_p0 = (0.5 * cb - 0.05).max(0.05);
        let mut out = vec![
            Estimate { name: "ρ", value: rho, sd: 0.0, unit: "kg/m³", source: GEOMETRY },
            Estimate { name: "L", value: l, sd: 0.0, unit: "m", source: GEOMETRY },
            Estimate { name: "d", value: d, sd: 0.0, unit: "m", source: GEOMETRY },
            Estimate { name: "m", value: m, sd: 0.0, unit: "kg", source: "ρ·C_B·L·B·d" },
            Estimate { name: "x_G", value: self.x_g, sd: 0.0, unit: "m", source: GEOMETRY },
            // a radius of gyration of a quarter length, as is usual for merchant ships
            Estimate {
                name: "I_zG",
                value: m * (0.25 * l).powi(2),
                sd: 0.0,
                unit: "kg m²",
                source: "m·(0.25 L)²",
            },
            Estimate {
                name: "m_x",
                value: m_x,
                sd: 0.0,
                unit: "kg",
                source: "0.05·m, the order of a full hull's surge added mass",
            },
            Estimate { name: "m_y", value: m_y, sd: 0.0, unit: "kg", source: CLARKE },
            Estimate { name: "J_z", value: j_z, sd: 0.0, unit: "kg m²", source: CLARKE },
            Estimate { name: "D_p", value: self.propeller_diameter, sd: 0.0, unit: "m", source: GEOMETRY },
            Estimate { name: "A_R", value: self.rudder_area, sd: 0.0, unit: "m²", source: GEOMETRY },
            Estimate {
                name: "η",
                value: self.propeller_diameter / self.rudder_span,
                sd: 0.0,
                unit: "",
                source: "D_p / H_R",
            },
            Estimate {
                name: "x_R",
                value: -0.5 * l,
                sd: 0.0,
                unit: "m",
                source: "the rudder at the stern, −L/2",
            },
            Estimate {
                name: "x_P",
                value: -0.48,
                sd: 0.0,
                unit: "",
                source: "the propeller just ahead of the rudder, x'_P = −0.48",
            },
            Estimate { name: "k_0", value: self.kt[0], sd: 0.0, unit: "", source: "the propeller's K_T(J)" },
            Estimate { name: "k_1", value: self.kt[1], sd: 0.0, unit: "", source: "the propeller's K_T(J)" },
            Estimate { name: "k_2", value: self.kt[2], sd: 0.0, unit: "", source: "the propeller's K_T(J)" },
            Estimate { name: "w_P0", value: w_p0, sd: 0.3 * w_p0, unit: "", source: TAYLOR },
            Estimate {
                name: "t_P",
                value: 0.6 * w_p0,
                sd: 0.3 * 0.6 * w_p0,
                unit: "",
                source: "t = 0.6·w, a single-screw rule of thumb",
            },
            // rudder lift gradient from the aspect ratio Λ = H_R²/A_R
            Estimate {
                name: "f_α",
                value: 6.13 * lambda / (lambda + 2.25),
                sd: 0.1 * 6.13 * lambda / (lambda + 2.25),
                unit: "",
                source: FUJII,
            },
            Estimate { name: "t_R", value: 0.3, sd: 0.15, unit: "", source: GENERIC },
            Estimate { name: "a_H", value: 0.3, sd: 0.15, unit: "", source: GENERIC },
            Estimate { name: "x_H", value: -0.45 * l, sd: 0.1 * l, unit: "m", source: GENERIC },
            Estimate { name: "ε", value: 1.0, sd: 0.3, unit: "", source: GENERIC },
            Estimate { name: "κ", value: 0.5, sd: 0.2, unit: "", source: GENERIC },
            Estimate { name: "l_R", value: -0.8, sd: 0.3, unit: "", source: GENERIC },
            Estimate { name: "γ_Rm", value: 0.5, sd: 0.25, unit: "", source: GENERIC },
            Estimate { name: "γ_Rp", value: 0.5, sd: 0.25, unit: "", source: GENERIC },
            // a single-screw propeller's side force at the stern turns the ship one way at
            // every speed (the asymmetry a polynomial library holds in its u², n² terms): a
            // yaw moment N_P·ρn²D_p⁵, scaled with the propeller's load and not with the
            // rudder's inflow, so the runs tell it from the rudder's zero; of the order of a
            // tenth of the thrust at L/2, 0 ± 0.1·k_0·(L/2)/D_p
            Estimate {
                name: "N_P",
                value: 0.0,
                sd: 0.1 * self.kt[0] * 0.5 * l / self.propeller_diameter,
                unit: "",
                source: "no formula from particulars: a propeller's side force of up to a tenth of its thrust, at the stern",
            },
            // the rudder indicator's zero: a record's offset, 0 ± 2°
            Estimate {
                name: "δ_0",
                value: 0.0,
                sd: 2f64.to_radians(),
                unit: "rad",
                source: "the rudder indicator's zero; a nuisance, its own in every run (--per-source δ_0: one per basin)",
            },
            // resistance: the straight run solves the propeller's rate for it, so it trades
            // against the propeller's parameters; a modest prior
            Estimate { name: "R_0", value: 0.02, sd: 0.01, unit: "", source: GENERIC },
        ];
        // the hull, Kijima et al. (1990), drift-angle form with β ≈ −v': Y'_v = −Y'_β,
        // Y'_vv (of v'|v'|) = −Y'_ββ, Y'_vvr = Y'_ββr, Y'_vrr = −Y'_βrr, and so for N;
        // Y'_r includes (m' + m'_x), the MMG form that has (m + m_x)ur on the other side
        let dob = d / b;
        let hull = [
            ("Y_v", -(std::f64::consts::FRAC_PI_2 * k + 1.4 * cbl), 0.3),
            ("Y_r", m_prime + m_x_prime - 1.5 * cbl, 0.5),
            ("N_v", -k, 0.3),
            ("N_r", -0.54 * k + k * k, 0.3),
            ("Y_vv", -(2.5 * dob * (1.0 - cb) + 0.5), 0.5),
            ("Y_rr", 0.343 * dob * cb - 0.07, 1.0),
            ("Y_vvr", 1.5 * dob * cb - 0.65, 1.0),
            ("Y_vrr", -(5.95 * dob * (1.0 - cb)), 1.0),
            ("N_vv", -(-0.96 * dob * (1.0 - cb) + 0.066), 1.0),
            ("N_rr", 0.5 * cbl - 0.09, 1.0),
            ("N_vvr", -(57.5 * cbl * cbl - 18.4 * cbl + 1.6), 1.0),
            ("N_vrr", 0.5 * dob * cb - 0.05, 1.0),
        ];
        for (name, value, rel) in hull {
            out.push(Estimate { name, value, sd: rel * value.abs().max(0.01), unit: "", source: KIJIMA });
        }
        // the surge derivatives: no formula of the same standing; small, wide priors
        for name in ["X_vv", "X_vr", "X_rr", "X_vvvv"] {
            out.push(Estimate { name, value: 0.0, sd: 0.05, unit: "", source: GENERIC });
        }
        out
    }

    /// The linear hull derivatives by Clarke et al. (1983) in the MMG's nondimensional form
    /// (their ½ρL²U units × L/d): a second, independent estimate beside Kijima's.
    pub fn clarke_linear(&self) -> [(&'static str, f64); 4] {
        let (l, b, d, cb) = (self.lpp, self.beam, self.draught, self.block_coefficient);
        let s = std::f64::consts::PI * (d / l).powi(2) * l / d;
        [
            ("Y_v", -s * (1.0 + 0.40 * cb * b / d)),
            ("Y_r", -s * (-0.5 + 2.2 * b / l - 0.080 * b / d)),
            ("N_v", -s * (0.5 + 2.4 * d / l)),
            ("N_r", -s * (0.25 + 0.039 * b / d - 0.56 * b / l)),
        ]
    }

    /// A grey-box MMG model file for the ship: the MMG standard model's propeller and rudder
    /// (Yasukawa & Yoshimura 2015) with the hull in Kijima's form, every parameter from
    /// [`Particulars::estimates`], those with a prior `free`. Where Clarke's linear
    /// derivatives differ from Kijima's by more than the prior's sd, the sd is widened to
    /// cover both.
    pub fn model(&self) -> Result<Model, ParticularsError> {
        self.check()?;
        let base = Model::parse(TEMPLATE, "mmg template")?;
        let estimates = self.estimates();
        let clarke = self.clarke_linear();
        let spec = base.edit(|file| {
            file.model.name = format!("{} (grey-box MMG model from its particulars)", self.name);
            file.model.provenance = "termid new-ship: MMG standard model (Yasukawa & Yoshimura 2015), hull in Kijima et al.'s (1990) form; parameters from the particulars, free with priors for termid estimate".into();
            file.model.notes = estimates
                .iter()
                .map(|e| format!("{} = {:.6}: {}", e.name, e.value, e.source))
                .collect();
            for e in &estimates {
                let Some(p) = file.parameters.get_mut(e.name) else { continue };
                p.value = e.value;
                p.unit = e.unit.into();
                if e.sd > 0.0 {
                    let other = clarke.iter().find(|(n, _)| *n == e.name).map(|(_, v)| *v);
                    let sd = other.map_or(e.sd, |c| e.sd.max((c - e.value).abs()));
                    p.free = true;
                    p.prior = Some(PriorSpec { value: e.value, sd });
                }
            }
            // the bounds that stop a diverging run, at the ship's own scale: the surge speed
            // from a hundredth of the approach speed to ten times it, the sway speed within five
            // times it, the yaw rate within r' = rL/U = 20 (a tight turn reaches r' ≈ 0.6)
            let u0 = self.u0;
            for s in file.states.iter_mut() {
                let (min, max) = match s.name.as_str() {
                    "u" => (0.01 * u0, 10.0 * u0),
                    "v" => (-5.0 * u0, 5.0 * u0),
                    "r" => (-20.0 * u0 / self.lpp, 20.0 * u0 / self.lpp),
                    _ => continue,
                };
                (s.min, s.max) = (Some(min), Some(max));
                if s.name == "u" {
                    s.initial = u0;
                }
            }
            if let Some(ship) = file.plugins.get_mut("ship").and_then(|t| t.as_table_mut()) {
                for (key, value) in [
                    ("lpp", self.lpp),
                    ("beam", self.beam),
                    ("draught", self.draught),
                    ("displacement", self.block_coefficient * self.lpp * self.beam * self.draught),
                    ("rudder_rate", self.rudder_rate),
                    ("rudder_limit", self.rudder_limit),
                    ("u0", self.u0),
                    ("density", self.density),
                ] {
                    ship.insert(key.into(), toml::Value::Float(value));
                }
            }
        })?;
        Ok(spec)
    }
}

/// The MMG model's structure with the hull in Kijima's form; every number is replaced.
const TEMPLATE: &str = include_str!("particulars_template.toml");

#[cfg(test)]
mod tests {
    use super::*;

    fn kvlcc2() -> Particulars {
        Particulars {
            name: "KVLCC2".into(),
            lpp: 7.0,
            beam: 1.27,
            draught: 0.46,
            block_coefficient: 0.81,
            x_g: 0.25,
            rudder_area: 0.0539,
            rudder_span: 0.345,
            propeller_diameter: 0.216,
            kt: tanker_propeller(),
            u0: 1.17,
            rudder_rate: 15.8,
            rudder_limit: 35.0,
            density: 1025.0,
        }
    }

    /// Particulars no displacement ship has (a unit slip, a key mistaken for another) and a
    /// steering gear or propeller a model file would refuse are refused naming the key; unusual but possible proportions pass with a caution.
    #[test]
    fn impossible_particulars_are_refused_and_unusual_ones_cautioned() {
        assert!(kvlcc2().check().is_ok());
        assert!(kvlcc2().cautions().is_empty(), "{:?}", kvlcc2().cautions());
        let refused = |edit: fn(&mut Particulars), key: &str| {
            let mut p = kvlcc2();
            edit(&mut p);
            let message = p.model().err().map(|e| e.to_string()).unwrap_or_default();
            assert!(message.contains(&format!("`{key}`")), "{key}: {message}");
        };
        refused(|p| p.draught = 46.0, "draught"); // centimetres
        refused(|p| p.beam = 127.0, "beam");
        refused(|p| p.x_g = 25.0, "x_g");
        refused(|p| p.x_g = f64::NAN, "x_g");
        refused(|p| p.rudder_limit = 95.0, "rudder_limit");
        // a model file would refuse the gear (and K_T) the template would be written with
        refused(|p| p.rudder_rate = 7900.0, "rudder_rate");
        refused(|p| p.kt[0] = f64::INFINITY, "kt");
        refused(|p| p.kt[0] = -0.3, "kt");
        // a slender fast hull: a model, with a word on the formulas' range
        let mut slender = kvlcc2();
        (slender.beam, slender.block_coefficient) = (0.7, 0.45);
        assert!(slender.model().is_ok());
        let cautions = slender.cautions().join("\n");
        assert!(cautions.contains("L/B = 10.000") && cautions.contains("C_B = 0.450"), "{cautions}");
    }

    /// The formulas against values worked by hand from the papers' expressions (KVLCC2,
    /// L = 7 m: T/L = 0.0657, B/T = 2.761, B/L = 0.1814, C_B·B/L = 0.1470, k = 0.1314).
    #[test]
    fn the_formulas_give_the_hand_worked_numbers() {
        let e = kvlcc2().estimates();
        let get = |n: &str| e.iter().find(|x| x.name == n).unwrap().value;
        let near = |a: f64, b: f64, tol: f64| (a - b).abs() <= tol * b.abs();
        assert!(near(get("Y_v"), -0.4121, 0.005), "{}", get("Y_v"));
        assert!(near(get("N_v"), -0.1314, 0.005), "{}", get("N_v"));
        assert!(near(get("N_r"), -0.0537, 0.01), "{}", get("N_r"));
        assert!(near(get("f_α"), 3.04, 0.01), "{}", get("f_α"));
        assert!(near(get("w_P0"), 0.355, 0.001), "{}", get("w_P0"));
        // Clarke's added mass m_y = 0.01357·1.190·½ρL³
        assert!(near(get("m_y"), 2840.0, 0.01), "{}", get("m_y"));
        let c = kvlcc2().clarke_linear();
        assert!(near(c[0].1, -0.391, 0.01) && near(c[2].1, -0.136, 0.01), "{c:?}");
    }

    /// In a steady current the ship's motion through the water is the still water's (Fossen
    /// 2011, sec. 10.3): the template's states are over ground, so its u and v are the still
    /// water's plus the current in the ship's axes, its track the still water's carried by the
    /// current, its heading and yaw rate the same.
    #[test]
    fn a_steady_current_carries_the_ship_and_changes_nothing_else() {
        use crate::sim::{simulate, Constant, Integrator, Settings, System};
        let still = kvlcc2().model().unwrap();
        let mut carried = still.clone();
        let (c_n, c_e) = (0.3, -0.2);
        assert!(carried.set_parameter("c_N", c_n) && carried.set_parameter("c_E", c_e));
        let settings = Settings { integrator: Integrator::Rk4, dt: 0.01, duration: 40.0, sample: 0.1 };
        let psi0: f64 = 0.4;
        // the current in the ship's axes at heading ψ (x0 north, y0 east)
        let c_u = |psi: f64| c_n * psi.cos() + c_e * psi.sin();
        let c_v = |psi: f64| c_e * psi.cos() - c_n * psi.sin();
        let run = |model: &Model, x0: &[f64]| {
            let system = System::new(model, &Default::default(), false).unwrap();
            // hard over to 20° at the propeller's rate of the approach
            simulate(&system, x0, &mut Constant(vec![20f64.to_radians(), 10.0]), &settings).unwrap()
        };
        let a = run(&still, &[1.17, 0.0, 0.0, psi0, 0.0, 0.0]);
        let b = run(&carried, &[1.17 + c_u(psi0), c_v(psi0), 0.0, psi0, 0.0, 0.0]);
        let turned = a.states[3].last().unwrap() - psi0;
        assert!(turned > 1.0, "the ship turns: {turned} rad");
        for k in 0..a.time.len() {
            let (t, psi) = (a.time[k], a.states[3][k]);
            let pairs = [
                (b.states[0][k] - c_u(psi), a.states[0][k]),
                (b.states[1][k] - c_v(psi), a.states[1][k]),
                (b.states[2][k], a.states[2][k]),
                (b.states[3][k], psi),
                (b.states[4][k] - c_n * t, a.states[4][k]),
                (b.states[5][k] - c_e * t, a.states[5][k]),
            ];
            for (i, (got, want)) in pairs.into_iter().enumerate() {
                assert!((got - want).abs() < 1e-6, "state {i} at t = {t}: {got} against {want}");
            }
        }
    }

    #[test]
    fn the_model_file_has_free_parameters_with_priors_and_simulates() {
        let model = kvlcc2().model().unwrap();
        let free = model.free_parameters();
        assert!(free.iter().any(|p| p.name == "Y_v" && p.prior.is_some()));
        assert!(free.iter().all(|p| p.prior.is_some_and(|(_, sd)| sd > 0.0)));
        // the file round-trips, and a ship simulates from it
        let again = Model::parse(&model.to_toml(), "kvlcc2_greybox.toml").unwrap();
        assert_eq!(again.free_parameters().len(), free.len());
        let bad = Particulars { block_coefficient: 1.4, ..kvlcc2() };
        assert!(bad.model().unwrap_err().to_string().contains("block_coefficient"));
    }
}
