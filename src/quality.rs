//! Quality settings: the knobs that trade run time for error, and the named presets
//! (`--quality draft|default|high|reference`) picked from the measured trade-off study
//! (`whitted bench`, docs/quality.md).
//!
//! Every knob is exact, or off, unless a preset or the user turns it on: samples per
//! pixel, adaptive anti-aliasing, the contribution cutoff, the maximum depth and the
//! precision (the fast `f32` tracer or the `f64` reference).

use std::fmt;
use std::str::FromStr;

use crate::render::{RenderOptions, Renderer};

/// Adaptive anti-aliasing: every pixel first gets `first` samples spread over it; only
/// pixels whose first samples, or whose 4-neighbours' means, differ by `threshold` or
/// more (largest colour component, linear values clamped to [0,1]) get the rest of the
/// `spp` samples. `threshold = 0` refines every pixel, which is plain anti-aliasing
/// bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    pub first: u32,
    pub threshold: f32,
}

impl Adaptive {
    /// Samples in the first pass unless told otherwise: a 2×2 spread.
    pub const FIRST: u32 = 4;

    /// The usual first pass with the given threshold.
    pub fn with_threshold(threshold: f32) -> Self {
        Adaptive {
            first: Self::FIRST,
            threshold,
        }
    }
}

/// One point of the time/error trade-off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quality {
    /// Samples per pixel (stratified and jittered beyond 1).
    pub spp: u32,
    /// `None`: every pixel gets `spp` samples.
    pub adaptive: Option<Adaptive>,
    /// Contribution cutoff ε: branches of path weight below it are not traced
    /// (0: exact). The fast tracer only; the reference traces everything.
    pub cutoff: f32,
    pub max_depth: u32,
    pub precision: Renderer,
}

impl Default for Quality {
    /// The SPEC's defaults: one centred sample, depth 5, everything exact.
    fn default() -> Self {
        Quality {
            spp: 1,
            adaptive: None,
            cutoff: 0.0,
            max_depth: 5,
            precision: Renderer::Fast,
        }
    }
}

impl Quality {
    /// The settings `opts` renders with.
    pub fn of(opts: &RenderOptions) -> Quality {
        Quality {
            spp: opts.image.spp,
            adaptive: opts.adaptive,
            cutoff: opts.cutoff,
            max_depth: opts.image.max_depth,
            precision: opts.renderer,
        }
    }

    /// Makes `opts` render with these settings (sizes, seed, region and threads stay).
    pub fn apply(&self, opts: &mut RenderOptions) {
        opts.image.spp = self.spp;
        opts.image.max_depth = self.max_depth;
        opts.adaptive = self.adaptive;
        opts.cutoff = self.cutoff;
        opts.renderer = self.precision;
    }

    /// Checks the knobs that [`crate::scene::ImageSettings::check`] does not.
    pub fn check(&self) -> Result<(), String> {
        if !(self.cutoff.is_finite() && self.cutoff >= 0.0) {
            return Err(format!(
                "cutoff {} is out of range: expected a number ≥ 0",
                self.cutoff
            ));
        }
        if let Some(a) = self.adaptive {
            if !(a.threshold.is_finite() && a.threshold >= 0.0) {
                return Err(format!(
                    "adaptive threshold {} is out of range: expected a number ≥ 0",
                    a.threshold
                ));
            }
            if a.first == 0 {
                return Err("adaptive first pass needs at least 1 sample".into());
            }
        }
        Ok(())
    }

    /// A short, unique, file-name-safe label such as `fast-spp16-aa0.03-eps0.01-d5`.
    pub fn label(&self) -> String {
        let mut s = match self.precision {
            Renderer::Fast => "fast".to_string(),
            Renderer::Reference => "f64".to_string(),
        };
        s += &format!("-spp{}", self.spp);
        if let Some(a) = self.adaptive {
            s += &format!("-aa{}", a.threshold);
            if a.first != Adaptive::FIRST {
                s += &format!("f{}", a.first);
            }
        }
        if self.cutoff > 0.0 {
            s += &format!("-eps{}", self.cutoff);
        }
        s += &format!("-d{}", self.max_depth);
        s
    }
}

/// The named presets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Preset {
    /// Interactive previews: one centred sample, depth 5, everything exact (the
    /// SPEC's defaults, what a render without options does).
    Draft,
    /// The knee of the measured time/error front on 3 of the 4 study scenes (and next
    /// to it on the fourth): RMSE about one 8-bit level.
    Default,
    /// The cheapest setting within 10% of the best error the fast tracer reached in
    /// the study (at a third of the time of 64 plain samples).
    High,
    /// The converged reference of the study: f64, 256 stratified spp, depth 16.
    Reference,
}

impl Preset {
    pub const ALL: [Preset; 4] = [
        Preset::Draft,
        Preset::Default,
        Preset::High,
        Preset::Reference,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Preset::Draft => "draft",
            Preset::Default => "default",
            Preset::High => "high",
            Preset::Reference => "reference",
        }
    }

    /// The settings of the preset. The values come from the study in docs/quality.md
    /// (`whitted bench`); re-run it before changing them.
    pub fn quality(self) -> Quality {
        match self {
            // The SPEC's defaults: what a render without options does.
            Preset::Draft => Quality::default(),
            Preset::Default => Quality {
                spp: 16,
                adaptive: Some(Adaptive::with_threshold(0.1)),
                cutoff: 0.0,
                max_depth: 16,
                precision: Renderer::Fast,
            },
            Preset::High => Quality {
                spp: 64,
                adaptive: Some(Adaptive::with_threshold(0.03)),
                cutoff: 0.0,
                max_depth: 16,
                precision: Renderer::Fast,
            },
            Preset::Reference => Quality {
                spp: 256,
                adaptive: None,
                cutoff: 0.0,
                max_depth: 16,
                precision: Renderer::Reference,
            },
        }
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Preset {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Preset::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| {
                format!("unknown quality \"{s}\": expected draft, default, high or reference")
            })
    }
}
