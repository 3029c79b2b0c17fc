//! The sky as light comes from it: the dome split into patches, what each receiver sees of them,
//! and the Perez sky that weighs them at each timestep.
//!
//! A sky patch is a direction, like a sun position, so the sky needs no engine of its own: its
//! views are ordinary [`crate::count::ViewRequest`]s to the same engines. Submodules:
//! - [`patches`]: Tregenza's 145 patches and Reinhart's subdivisions, Radiance's layout, and
//!   each receiver's cosine-weighted solid angle per patch;
//! - [`views`]: every receiver's sky views, once per model (and per leaf state), and the view
//!   factors made of them;
//! - [`perez`]: the Perez 1990 all-weather sky, as EnergyPlus applies it;
//! - [`energyplus`]: EnergyPlus's own 144-direction diffuse shading ratios;
//! - [`directions`]: fractions for given sun directions (SAM's azimuth × altitude table);
//! - [`luminance`]: weather-free luminance distributions (the CIE standard overcast sky, which
//!   BRE 209's vertical sky component is defined under, and the uniform sky);
//! - [`all_weather`]: the Perez all-weather luminance distribution, as Radiance's gendaymtx;
//! - [`model`]: the `sky_model` choice among them, and each hour's patch radiances.
//!
//! Combining them with the beam per timestep is [`crate::export::irradiation`]'s.

pub mod all_weather;
pub mod directions;
pub mod energyplus;
pub mod luminance;
pub mod model;
pub mod patches;
pub mod perez;
pub mod views;
