//! The model's options (shared by `inspect` and the main command): its size and units,
//! repairs and simplification, as given and resolved.

use std::path::Path;

use serde::Deserialize;

use super::defaults;
use super::values::{simplify_modes, TargetEdges};
use crate::error::{Error, Result};
use crate::units::{parse_length, LengthUnit, MAX_LENGTH_MM};

/// Options that describe the model and its physical size (shared by `inspect` and the
/// main command). Every field is optional so that the command line and the TOML file
/// can be merged; [`ModelOptions::resolve`] fills in the defaults.
#[derive(Clone, Debug, Default, Deserialize, clap::Args)]
#[serde(rename_all = "kebab-case")]
pub struct ModelOptions {
    /// Longest side of the model's bounding box when built, with a unit: 4ft, 1.2m,
    /// 48in, 600mm. Overrides --units.
    #[arg(long, value_name = "LENGTH")]
    pub size: Option<String>,

    /// What one model unit is, when --size is not given.
    #[arg(long, value_name = "UNIT")]
    pub units: Option<LengthUnit>,

    /// Extra factor applied after --size or --units.
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    pub scale: Option<f64>,

    /// Merge vertices that share a position where the mesh stays manifold (OBJ and OFF
    /// keep them apart by default; STL is always welded).
    #[arg(long)]
    #[serde(default)]
    pub weld: bool,

    /// Faces whose planarity error (largest corner distance from the best-fit plane,
    /// divided by the face's diameter) exceeds this are non-planar.
    #[arg(long, value_name = "FRACTION")]
    pub planarity_tol: Option<f64>,

    /// Simplify a triangle mesh to about this many edges (within 2 %), keeping its
    /// holes and genus; `auto` simplifies only a model too detailed for its size, to
    /// the budget at which every panel holds its id and holes (tried, and named in the
    /// report).
    #[arg(long, value_name = "N|auto", conflicts_with = "target_faces")]
    pub target_edges: Option<TargetEdges>,

    /// Simplify a triangle mesh to about this many faces, keeping its holes and genus.
    #[arg(long, value_name = "N")]
    pub target_faces: Option<usize>,

    /// What simplification favours: regular (even triangle sizes and shapes, so
    /// panels of one size) or accurate (the closest surface: few
    /// large triangles where the model is flat, many small ones where it curves).
    #[arg(long, value_name = "MODE", value_parser = simplify_modes())]
    pub simplify_mode: Option<crate::mesh::simplify::SimplifyMode>,

    /// Remove connected components with fewer than N faces (stray fragments of a scan,
    /// loose parts too small to build).
    #[arg(long, value_name = "N")]
    pub min_component: Option<usize>,

    /// Close every hole of the mesh with a face along its rim (a scan's open base, a
    /// patch model's open rims), joining open seams shut: short rim edges no longer
    /// limit simplification, and the woven scheme can weave the model.
    #[arg(long)]
    #[serde(default)]
    pub fill_holes: bool,
}

/// How model units become millimetres.
#[derive(Clone, Debug, PartialEq)]
pub struct Scaling {
    /// `Some(mm)`: the longest bounding-box side becomes this many millimetres.
    pub size: Option<f64>,
    /// Millimetres per model unit when `size` is not given.
    pub unit_mm: f64,
    /// Extra factor.
    pub scale: f64,
}

impl Scaling {
    /// Millimetres per model unit for a model whose longest bounding-box side is
    /// `longest_side` model units.
    pub fn mm_per_unit(&self, longest_side: f64) -> f64 {
        let base = match self.size {
            Some(mm) if longest_side > 0.0 => mm / longest_side,
            _ => self.unit_mm,
        };
        base * self.scale
    }
}

/// The smallest model, longest side when built (mm), worth unfolding: below it every
/// panel is smaller than the laser's kerf.
pub const MIN_BUILT_MM: f64 = 0.1;

impl ModelSettings {
    /// Millimetres per model unit for a model whose longest side is `longest_side`
    /// model units, refusing a build smaller than [`MIN_BUILT_MM`] or longer than
    /// [`MAX_LENGTH_MM`]: at such sizes the geometry degenerates or overflows
    /// downstream, where no message could name the cause. The error names what made
    /// the size: `--scale` (when not 1) or `--size` as usage errors, otherwise the
    /// model's own coordinates in `--units` as an input error.
    pub fn checked_mm_per_unit(&self, model: &Path, longest_side: f64) -> Result<f64> {
        let scaling = &self.scaling;
        let mm_per_unit = scaling.mm_per_unit(longest_side);
        let built_mm = longest_side * mm_per_unit;
        if built_mm.is_finite() && (MIN_BUILT_MM..=MAX_LENGTH_MM).contains(&built_mm) {
            return Ok(mm_per_unit);
        }
        let bound = if built_mm.is_finite() && built_mm < MIN_BUILT_MM {
            format!("smaller than {MIN_BUILT_MM} mm")
        } else {
            "more than 1 km".to_string()
        };
        let built = format!("{} mm across", crate::units::short_number(built_mm));
        if scaling.scale != 1.0 {
            return Err(Error::Usage(format!(
                "--scale: {} makes {} {built}, {bound}; use a scale nearer 1 or give --size",
                crate::units::short_number(scaling.scale),
                model.display()
            )));
        }
        if let Some(size) = scaling.size {
            return Err(Error::Usage(format!(
                "--size: {} mm is {bound}; give a size between 0.1 mm and 1 km",
                crate::units::short_number(size)
            )));
        }
        Err(crate::error::InputError::new(
            model,
            crate::error::Location::File,
            format!(
                "the model is {built} when built (one model unit = {} mm), {bound}",
                scaling.unit_mm
            ),
            "give --size with a unit (like --size 4ft) or the right --units",
        )
        .into())
    }
}

/// Resolved model options.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelSettings {
    /// Physical scaling.
    pub scaling: Scaling,
    /// Weld coincident vertices where manifold.
    pub weld: bool,
    /// Planarity tolerance (fraction of face diameter).
    pub planarity_tol: f64,
    /// Simplification budget, if any.
    pub budget: Option<crate::mesh::simplify::Budget>,
    /// `--target-edges auto`: a model too detailed for its size is simplified to the
    /// budget its build finds (`budget` is then `None`).
    pub auto_budget: bool,
    /// What simplification favours.
    pub simplify_mode: crate::mesh::simplify::SimplifyMode,
    /// Components with fewer faces than this are removed (0 keeps all).
    pub min_component: usize,
    /// Close every boundary loop (a face along its rim; open seams joined shut).
    pub fill_holes: bool,
    /// Keep the surface as it was before simplifying
    /// ([`crate::mesh::PreparedModel::unsimplified`]): the job's scheme keeps a
    /// distance to the model as given.
    pub keep_unsimplified: bool,
}

impl ModelOptions {
    /// Fills fields missing here from `other` (the configuration file).
    pub fn or(self, other: ModelOptions) -> ModelOptions {
        ModelOptions {
            size: self.size.or(other.size),
            units: self.units.or(other.units),
            scale: self.scale.or(other.scale),
            weld: self.weld || other.weld,
            planarity_tol: self.planarity_tol.or(other.planarity_tol),
            target_edges: self.target_edges.or(other.target_edges),
            target_faces: self.target_faces.or(other.target_faces),
            simplify_mode: self.simplify_mode.or(other.simplify_mode),
            min_component: self.min_component.or(other.min_component),
            fill_holes: self.fill_holes || other.fill_holes,
        }
    }

    /// Checks every value and fills in defaults.
    pub fn resolve(&self) -> Result<ModelSettings> {
        let size = match &self.size {
            Some(text) => {
                let mm = parse_length(text).map_err(|e| Error::Usage(format!("--size: {e}")))?;
                if mm <= 0.0 {
                    return Err(Error::Usage(format!("--size: '{text}' must be positive")));
                }
                Some(mm)
            }
            None => None,
        };
        let scale = self.scale.unwrap_or(defaults::SCALE);
        if !(scale.is_finite() && scale > 0.0) {
            return Err(Error::Usage(format!(
                "--scale: {scale} must be a positive number"
            )));
        }
        let planarity_tol = self.planarity_tol.unwrap_or(defaults::PLANARITY_TOL);
        if !(planarity_tol.is_finite() && planarity_tol > 0.0 && planarity_tol < 1.0) {
            return Err(Error::Usage(format!(
                "--planarity-tol: {planarity_tol} must be between 0 and 1 (a fraction of the face size)"
            )));
        }
        let budget = match (self.target_edges, self.target_faces) {
            (Some(_), Some(_)) => {
                return Err(Error::Usage(
                    "give --target-edges or --target-faces, not both".to_string(),
                ))
            }
            (Some(TargetEdges::Count(0)), _) | (_, Some(0)) => {
                return Err(Error::Usage(
                    "--target-edges and --target-faces must be positive".to_string(),
                ))
            }
            (Some(TargetEdges::Auto), None) => None,
            (Some(TargetEdges::Count(e)), None) => Some(crate::mesh::simplify::Budget::Edges(e)),
            (None, Some(f)) => Some(crate::mesh::simplify::Budget::Faces(f)),
            (None, None) => None,
        };
        Ok(ModelSettings {
            budget,
            auto_budget: self.target_edges == Some(TargetEdges::Auto),
            simplify_mode: self.simplify_mode.unwrap_or_default(),
            min_component: self.min_component.unwrap_or(defaults::MIN_COMPONENT),
            scaling: Scaling {
                size,
                unit_mm: self.units.unwrap_or(defaults::UNITS).mm(),
                scale,
            },
            weld: self.weld,
            planarity_tol,
            fill_holes: self.fill_holes,
            keep_unsimplified: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaling_by_size_and_units() {
        let by_size = Scaling {
            size: Some(1219.2),
            unit_mm: 1.0,
            scale: 1.0,
        };
        assert!((by_size.mm_per_unit(2.0) - 609.6).abs() < 1e-9);
        let by_units = Scaling {
            size: None,
            unit_mm: LengthUnit::Cm.mm(),
            scale: 2.0,
        };
        assert_eq!(by_units.mm_per_unit(123.0), 20.0);
    }
}
