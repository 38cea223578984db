//! The statistics of sampled renders, as pure functions: how far an image
//! is from its reference ([`metrics`]: relMSE and FLIP), a quantity's mean
//! and spread over seeds ([`spread`]), the slope of error against samples or
//! time on log-log axes ([`fit`]), whether a direction sampler draws from
//! the density it claims ([`chi2`]), and the exact image of a scene whose
//! answer has a closed form ([`analytic`]).

pub mod analytic;
pub mod chi2;
pub mod fit;
pub mod metrics;
pub mod spread;
