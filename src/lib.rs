//! termid identifies equations of motion from time series. Candidate terms are written as
//! text in a small language ([`term`]), evaluated on data ([`data`]: frames, units,
//! resampling, derivative methods), and a regression back-end ([`select`]) chooses the terms
//! that matter ([`identify`]). Identified models ([`model`]) are simulated ([`sim`]), checked
//! against runs ([`diagnose`]) and drawn from their coefficients' covariance
//! ([`uncertainty`]); fields add to the core through [`plugin`]s, ship manoeuvring
//! ([`ship`]) the first.
#![warn(missing_docs)]

pub mod budget;
pub mod contain;
pub mod data;
pub mod diagnose;
pub mod identify;
mod linalg;
pub mod model;
pub mod output;
#[cfg(feature = "plot")]
pub mod plot;
pub mod plugin;
pub mod plugins;
pub mod recipe;
pub mod select;
pub mod ship;
pub mod sim;
pub mod term;
pub mod uncertainty;
