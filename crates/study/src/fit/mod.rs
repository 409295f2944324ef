//! Inverse identification (`shpb fit`, issue 44): least squares and the ensemble-MCMC posterior
//! ([`mcmc`], the affine-invariant stretch-move sampler).

pub mod mcmc;
