//! What the viewer tells the user: the window title, the key list, and (with
//! `WHITTED_STATS=1`) timing lines on stderr.

/// The state of the current view, for the title.
#[derive(Clone, Debug, PartialEq)]
pub enum Progress {
    /// Submitted, nothing shown yet.
    Rendering,
    /// The coarse preview is on screen.
    Preview {
        seconds: f64,
    },
    /// `samples` of `target` samples per pixel are on screen.
    Samples {
        samples: u32,
        target: u32,
        seconds: f64,
    },
    Failed,
}

/// The window title: `whitted - SCENE - WxH - PROGRESS`, and for frame `k` of `n` of an
/// animation `whitted - SCENE - WxH - frame K/N - PROGRESS`, `K` counted from 0 as in
/// the numbered files of `whitted render`. It ends in `- done` exactly when every
/// sample of the current view is on screen (the tests wait for that).
pub fn title_of_frame(
    scene: &str,
    width: u32,
    height: u32,
    frame: Option<(u32, u32)>,
    progress: &Progress,
) -> String {
    let ms = |s: f64| s * 1000.0;
    let state = match *progress {
        Progress::Rendering => "rendering".to_string(),
        Progress::Preview { seconds } => format!("preview - {:.1} ms", ms(seconds)),
        Progress::Samples {
            samples,
            target,
            seconds,
        } => {
            let done = if samples >= target { " - done" } else { "" };
            format!("{samples}/{target} spp - {:.1} ms{done}", ms(seconds))
        }
        Progress::Failed => "render failed".to_string(),
    };
    match frame {
        None => format!("whitted - {scene} - {width}x{height} - {state}"),
        Some((k, n)) => format!("whitted - {scene} - {width}x{height} - frame {k}/{n} - {state}"),
    }
}

pub const HELP: &str = "\
whitted viewer keys:
  S                  save the image on screen as PNG and PPM (numbered names);
                     the line printed gives the view's camera
  Esc, Q             quit
  arrows             move forward/back, left/right
  PageUp, PageDown   move up/down
  mouse drag         orbit around the look-at point
  mouse wheel        zoom (field of view)
  click              inspect a pixel: its ray tree is printed
  R                  reset the camera
  P                  play or pause an animated scene (at its fps, or as fast as
                     the frames render)
  , .                step one frame back, forward (an edited camera stays put
                     until R)
  H                  print this list";

/// Whether `WHITTED_STATS` asks for timing lines.
pub fn stats_enabled(value: Option<&str>) -> bool {
    matches!(value.map(str::trim), Some(v) if !v.is_empty() && v != "0")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The title of a still scene.
    fn title(scene: &str, width: u32, height: u32, progress: &Progress) -> String {
        title_of_frame(scene, width, height, None, progress)
    }

    #[test]
    fn the_title_says_done_only_when_complete() {
        let t = title(
            "hw3",
            320,
            180,
            &Progress::Samples {
                samples: 4,
                target: 4,
                seconds: 0.0123,
            },
        );
        assert_eq!(t, "whitted - hw3 - 320x180 - 4/4 spp - 12.3 ms - done");
        let partial = title(
            "hw3",
            320,
            180,
            &Progress::Samples {
                samples: 2,
                target: 4,
                seconds: 0.5,
            },
        );
        assert!(!partial.contains("done") && partial.contains("2/4 spp"));
        for p in [
            Progress::Rendering,
            Progress::Preview { seconds: 0.01 },
            Progress::Failed,
        ] {
            let t = title("x", 1, 1, &p);
            assert!(t.starts_with("whitted - x - 1x1 - ") && !t.contains("done"));
        }
    }

    #[test]
    fn an_animated_scene_shows_its_frame_number() {
        let done = Progress::Samples {
            samples: 1,
            target: 1,
            seconds: 0.002,
        };
        assert_eq!(
            title_of_frame("spin", 64, 36, Some((3, 12)), &done),
            "whitted - spin - 64x36 - frame 3/12 - 1/1 spp - 2.0 ms - done"
        );
        assert_eq!(
            title_of_frame("spin", 64, 36, None, &done),
            title("spin", 64, 36, &done)
        );
    }

    #[test]
    fn stats_switch() {
        assert!(!stats_enabled(None));
        assert!(!stats_enabled(Some("0")));
        assert!(!stats_enabled(Some("")));
        assert!(stats_enabled(Some("1")));
    }
}
