//! The year: from a handful of counted views to a sunlit fraction at every EnergyPlus timestep.
//!
//! Owns *when*: the timesteps EnergyPlus wants and the sparse samples that are counted instead
//! ([`samples`]), the leaf calendar foliage follows through the seasons ([`season`]), the one
//! resolver of a run's settings that the CLI and the web share ([`settings`]), the B-spline
//! surface over (day, time of day) through the samples ([`spline`]), and the annual run that ties
//! them to an [`Engine`](crate::count::Engine): what to count, fitting, refining where shadow
//! edges sweep too fast, and surviving a lost GPU device ([`annual`]), with the refined steps that a certificate proves dark
//! or lit set without a view ([`certified`]) and the rest counted by bisection in days, interpolated
//! between counted days where that is as good as counting ([`refine`]); a model whose EnergyPlus shading updates
//! periodically, one sun a period ([`periodic`]); the fitted surfaces kept
//! to evaluate at any instant ([`fitted`], a viewer's time slider); and the beam that exterior
//! windows let onto their zones' inside faces at every timestep ([`interior_beam`]). It knows nothing of pixels
//! (that is [`crate::count`]) or of files (that is [`crate::export`]).

pub mod annual;
mod certified;
pub mod fitted;
pub mod interior_beam;
mod periodic;
mod refine;
pub mod samples;
pub mod season;
pub mod settings;
pub mod spline;
pub mod transmitting;
