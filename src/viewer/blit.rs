//! Getting top-down RGBA bytes onto the window: `pixels` (wgpu) when it finds a GPU,
//! else `softbuffer` (also when wgpu's adapter is a CPU rasterizer such as llvmpipe).
//! `WHITTED_BLIT=pixels|softbuffer` forces one.
//!
//! `pixels` keeps its texture `Rgba8UnormSrgb` and picks an sRGB surface, so the two
//! conversions cancel and the window shows the bytes as they are, like the files.

use std::num::NonZeroU32;
use std::sync::Arc;

use pixels::wgpu::{AdapterInfo, DeviceType};
use pixels::{Pixels, PixelsBuilder, SurfaceTexture};
use winit::window::Window;

use super::buffer::{blit_xrgb, window_to_pixel};

/// Which blitter the user asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Choice {
    /// `pixels`, falling back to `softbuffer`.
    Auto,
    Pixels,
    Softbuffer,
}

/// Reads `WHITTED_BLIT` (its value, if set).
pub fn parse_choice(value: Option<&str>) -> Result<Choice, String> {
    match value.map(str::trim) {
        None | Some("") => Ok(Choice::Auto),
        Some(v) if v.eq_ignore_ascii_case("pixels") => Ok(Choice::Pixels),
        Some(v) if v.eq_ignore_ascii_case("softbuffer") => Ok(Choice::Softbuffer),
        Some(v) => Err(format!(
            "WHITTED_BLIT={v} is not understood: use `pixels` or `softbuffer`"
        )),
    }
}

pub enum Blitter {
    Pixels {
        pixels: Box<Pixels<'static>>,
        buffer: (u32, u32),
    },
    Soft {
        surface: softbuffer::Surface<Arc<Window>, Arc<Window>>,
        surface_size: (u32, u32),
    },
}

impl Blitter {
    /// The blitter for `window` (whose inner size is `size`, not 0×0). With `Auto`,
    /// `pixels` on a GPU; when it fails, or when the adapter wgpu picks is a CPU
    /// rasterizer (llvmpipe, lavapipe: wgpu prefers any GPU to those), the reason is
    /// printed and `softbuffer` used instead. On a CPU, `pixels` draws each 1280×720
    /// frame in ~15 ms of the cores the render needs, `softbuffer` in ~1 ms.
    /// Either way one line on stderr says which blitter draws ([`Blitter::line`]).
    pub fn new(window: &Arc<Window>, size: (u32, u32), choice: Choice) -> Result<Blitter, String> {
        let (blitter, fallback) = match choice {
            Choice::Pixels => (Self::pixels(window, size)?, None),
            Choice::Softbuffer => (Self::soft(window, size)?, None),
            Choice::Auto => {
                let reason = match Self::pixels(window, size) {
                    Ok(blitter) => match blitter.adapter_info() {
                        Some(info) if info.device_type == DeviceType::Cpu => {
                            format!("the graphics adapter, {}, is a CPU", info.name)
                        }
                        _ => return Ok(blitter.announced(choice, None)),
                    },
                    Err(e) => e,
                };
                (Self::soft(window, size)?, Some(reason))
            }
        };
        Ok(blitter.announced(choice, fallback.as_deref()))
    }

    /// This blitter, once [`Blitter::line`] is printed.
    fn announced(self, choice: Choice, fallback: Option<&str>) -> Blitter {
        eprintln!(
            "{}",
            Blitter::line(self.name(), self.adapter().as_deref(), choice, fallback)
        );
        self
    }

    /// The line that says which blitter draws: `pixels` and its adapter, or
    /// `softbuffer`; why, when `pixels` was turned down (`fallback`); and the
    /// variable, when `WHITTED_BLIT` chose.
    pub fn line(
        name: &str,
        adapter: Option<&str>,
        choice: Choice,
        fallback: Option<&str>,
    ) -> String {
        let on = adapter.map(|a| format!(" on {a}")).unwrap_or_default();
        match (fallback, choice) {
            (Some(reason), _) => format!("whitted: {reason}; drawing with {name} instead"),
            (None, Choice::Auto) => format!("whitted: drawing with {name}{on}"),
            (None, _) => format!("whitted: drawing with {name}{on} (WHITTED_BLIT={name})"),
        }
    }

    /// `pixels`' adapter (`None` for `softbuffer`).
    fn adapter_info(&self) -> Option<AdapterInfo> {
        match self {
            Blitter::Pixels { pixels, .. } => Some(pixels.adapter().get_info()),
            Blitter::Soft { .. } => None,
        }
    }

    /// `pixels`' adapter: its name and kind (`None` for `softbuffer`).
    pub fn adapter(&self) -> Option<String> {
        let info = self.adapter_info()?;
        Some(format!("{} ({:?})", info.name, info.device_type))
    }

    fn pixels(window: &Arc<Window>, (w, h): (u32, u32)) -> Result<Blitter, String> {
        let texture = SurfaceTexture::new(w.max(1), h.max(1), Arc::clone(window));
        let pixels = PixelsBuilder::new(w.max(1), h.max(1), texture)
            // A ray tracer has no use for vsync, and it must never hold up the loop.
            .enable_vsync(false)
            .build()
            .map_err(|e| format!("pixels cannot draw in the window: {e}"))?;
        Ok(Blitter::Pixels {
            pixels: Box::new(pixels),
            buffer: (w.max(1), h.max(1)),
        })
    }

    fn soft(window: &Arc<Window>, size: (u32, u32)) -> Result<Blitter, String> {
        let context = softbuffer::Context::new(Arc::clone(window))
            .map_err(|e| format!("softbuffer cannot open the display: {e}"))?;
        let surface = softbuffer::Surface::new(&context, Arc::clone(window))
            .map_err(|e| format!("softbuffer cannot draw in the window: {e}"))?;
        let mut blitter = Blitter::Soft {
            surface,
            surface_size: (0, 0),
        };
        blitter.resize_surface(size)?;
        Ok(blitter)
    }

    pub fn name(&self) -> &'static str {
        match self {
            Blitter::Pixels { .. } => "pixels",
            Blitter::Soft { .. } => "softbuffer",
        }
    }

    /// The window's inner size changed (never called with 0×0).
    pub fn resize_surface(&mut self, (w, h): (u32, u32)) -> Result<(), String> {
        let (Some(nw), Some(nh)) = (NonZeroU32::new(w), NonZeroU32::new(h)) else {
            return Ok(());
        };
        match self {
            Blitter::Pixels { pixels, .. } => pixels
                .resize_surface(w, h)
                .map_err(|e| format!("cannot resize the surface: {e}")),
            Blitter::Soft {
                surface,
                surface_size,
            } => {
                surface
                    .resize(nw, nh)
                    .map_err(|e| format!("cannot resize the surface: {e}"))?;
                *surface_size = (w, h);
                Ok(())
            }
        }
    }

    /// Shows `rgba` (`w`×`h`, top-down) at 1:1, centred if the window is larger.
    pub fn draw(&mut self, rgba: &[u8], w: u32, h: u32) -> Result<(), String> {
        match self {
            Blitter::Pixels { pixels, buffer } => {
                if *buffer != (w, h) {
                    pixels
                        .resize_buffer(w, h)
                        .map_err(|e| format!("cannot resize the pixel buffer: {e}"))?;
                    *buffer = (w, h);
                }
                pixels.frame_mut().copy_from_slice(rgba);
                pixels.render().map_err(|e| format!("cannot draw: {e}"))
            }
            Blitter::Soft {
                surface,
                surface_size,
            } => {
                let (sw, sh) = *surface_size;
                if sw == 0 || sh == 0 {
                    return Ok(());
                }
                let mut buffer = surface
                    .buffer_mut()
                    .map_err(|e| format!("cannot draw: {e}"))?;
                blit_xrgb(rgba, w, h, &mut buffer, sw, sh);
                buffer.present().map_err(|e| format!("cannot draw: {e}"))
            }
        }
    }

    /// The image pixel `(i, j)` (`j` from the bottom) under window position `(x, y)`
    /// for an image of `w`×`h` drawn by [`Self::draw`] in a window of `window` size.
    pub fn pixel_at(
        &self,
        (x, y): (f64, f64),
        (w, h): (u32, u32),
        window: (u32, u32),
    ) -> Option<(u32, u32)> {
        match self {
            Blitter::Pixels { pixels, buffer } if *buffer == (w, h) => pixels
                .window_pos_to_pixel((x as f32, y as f32))
                .ok()
                .map(|(i, row)| (i as u32, h - 1 - row as u32)),
            _ => window_to_pixel(x, y, w, h, window.0, window.1),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_environment_variable_picks_the_blitter() {
        assert_eq!(parse_choice(None), Ok(Choice::Auto));
        assert_eq!(parse_choice(Some("")), Ok(Choice::Auto));
        assert_eq!(parse_choice(Some("pixels")), Ok(Choice::Pixels));
        assert_eq!(parse_choice(Some("SoftBuffer")), Ok(Choice::Softbuffer));
        let err = parse_choice(Some("gl")).unwrap_err();
        assert!(err.contains("WHITTED_BLIT=gl"), "{err}");
    }

    #[test]
    fn one_line_says_which_blitter_draws_either_way() {
        let gpu = Some("NVIDIA GeForce (DiscreteGpu)");
        assert_eq!(
            Blitter::line("pixels", gpu, Choice::Auto, None),
            "whitted: drawing with pixels on NVIDIA GeForce (DiscreteGpu)"
        );
        assert_eq!(
            Blitter::line("pixels", gpu, Choice::Pixels, None),
            "whitted: drawing with pixels on NVIDIA GeForce (DiscreteGpu) (WHITTED_BLIT=pixels)"
        );
        assert_eq!(
            Blitter::line("softbuffer", None, Choice::Softbuffer, None),
            "whitted: drawing with softbuffer (WHITTED_BLIT=softbuffer)"
        );
        assert_eq!(
            Blitter::line(
                "softbuffer",
                None,
                Choice::Auto,
                Some("the graphics adapter, llvmpipe, is a CPU")
            ),
            "whitted: the graphics adapter, llvmpipe, is a CPU; drawing with softbuffer instead"
        );
    }
}
