//! Animated GIFs of episodes: an episode stepped again through the actions it took, drawn from
//! above ([`render::top_down`]) or first-person ([`render::first_person()`]) every `stride` steps.
//!
//! Stepping the model again, rather than drawing logged numbers, gives exact frames (the pose after
//! the last action included) from nothing but the scene, the configuration and the actions, so a
//! replay needs neither the policy nor its randomness; logged poses, when given, are checked
//! against the model at every step, so a log from another scene or configuration is an error that
//! names the step instead of a wrong picture.
//!
//! Every picture uses the few colours of [`render::PALETTE`], so the GIF has one global palette
//! with exact colours, and each frame stores only the rectangle that changed since the one before.

use crate::geometry::Point;
use crate::render;
use crate::sim::{Action, Episode, Pose};
use image::RgbImage;
use std::io::Write;

/// Largest difference between a logged pose and the model's that still counts as the same: logs
/// keep 3 decimals, so rounding alone gives at most 0.0005 px or degree.
const POSE_TOLERANCE: f64 = 2e-3;

/// How an episode is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// The whole scene from above, with the path so far.
    TopDown,
    /// The paper's first-person view: heading up, the circle of laser range, rays, goal arrow.
    FirstPerson,
}

impl std::str::FromStr for View {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "top" => Ok(View::TopDown),
            "first" => Ok(View::FirstPerson),
            other => Err(format!("{other:?}: expected `top` or `first`")),
        }
    }
}

impl View {
    /// The name on the command line: `top` or `first`.
    pub fn name(self) -> &'static str {
        match self {
            View::TopDown => "top",
            View::FirstPerson => "first",
        }
    }
}

/// How an animation is drawn and timed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GifOptions {
    /// What each frame shows.
    pub view: View,
    /// A frame every `stride` steps (the first and last states always get one); at least 1.
    pub stride: u32,
    /// Top-down view: picture pixels per scene px.
    pub scale: f64,
    /// First-person view: side of the square picture, pixels.
    pub size_px: u32,
    /// First-person view of a team: the robot whose view it is (0 for a lone robot).
    pub follow: usize,
    /// Time each frame shows, hundredths of a second (the GIF unit).
    pub frame_delay_cs: u16,
    /// Time the last frame shows before the animation loops, hundredths of a second.
    pub last_frame_delay_cs: u16,
}

impl Default for GifOptions {
    fn default() -> Self {
        Self {
            view: View::TopDown,
            stride: 1,
            scale: 0.4,
            size_px: 240,
            follow: 0,
            frame_delay_cs: 5,
            last_frame_delay_cs: 150,
        }
    }
}

/// An animation that could not be made.
#[derive(Debug, thiserror::Error)]
pub enum AnimationError {
    /// A logged pose is not where the model, stepping the logged actions, puts the robot.
    #[error(
        "step {step}: the log has the robot at ({:.3}, {:.3}, {:.3} deg) but stepping the logged \
         actions from the episode's start puts it at ({:.3}, {:.3}, {:.3} deg): the log does not \
         come from this scene and configuration, or is not one episode's consecutive steps",
        logged.x, logged.y, logged.z_deg, model.x, model.y, model.z_deg
    )]
    Diverged {
        /// The step (1-based) whose starting pose differs.
        step: usize,
        /// The pose in the log.
        logged: Pose,
        /// The pose the model gives.
        model: Pose,
    },
    /// The model's episode ended before the log's actions did.
    #[error("step {step}: the episode already ended ({status}) but the log goes on")]
    EndedEarly {
        /// The first step (1-based) the model could not take.
        step: usize,
        /// How the model's episode ended.
        status: &'static str,
    },
    /// The logged poses and actions are not one per step.
    #[error("{poses} logged poses for {actions} actions: expected one pose per action")]
    Mismatch {
        /// Number of poses.
        poses: usize,
        /// Number of actions.
        actions: usize,
    },
    /// A frame is larger than a GIF can hold (65535 pixels a side).
    #[error("frames of {width} x {height} pixels are too large for a GIF (65535 at most)")]
    TooLarge {
        /// Frame width, pixels.
        width: u32,
        /// Frame height, pixels.
        height: u32,
    },
    /// The encoder failed.
    #[error("cannot encode the GIF: {0}")]
    Encode(#[from] gif::EncodingError),
}

/// An encoded animation.
#[derive(Clone, Debug)]
pub struct Animation {
    /// The GIF file's bytes.
    pub bytes: Vec<u8>,
    /// Number of frames.
    pub frames: usize,
    /// Number of steps shown.
    pub steps: usize,
    /// Frame width and height, pixels.
    pub size: (u32, u32),
}

/// Draws `episode` from its current state through `actions`, a frame every `options.stride`
/// steps. `logged`, when given, holds the pose before each action, as a data log records it; each
/// must match the model's.
///
/// Stepping the model again, rather than drawing logged numbers, gives exact frames (the pose after
/// the last action included) from nothing but the scene, the configuration and the actions, so a
/// replay needs neither the policy nor its randomness; logged poses, when given, are checked
/// against the model at every step, so a log from another scene or configuration is an error that
/// names the step instead of a wrong picture.
pub fn animate(
    mut episode: Episode,
    actions: &[Action],
    logged: Option<&[Pose]>,
    options: &GifOptions,
) -> Result<Animation, AnimationError> {
    if let Some(poses) = logged {
        if poses.len() != actions.len() {
            return Err(AnimationError::Mismatch {
                poses: poses.len(),
                actions: actions.len(),
            });
        }
    }
    let stride = options.stride.max(1) as usize;
    let mut path: Vec<Point> = vec![episode.pose().position()];
    let draw = |episode: &Episode, path: &[Point]| match options.view {
        View::TopDown => render::top_down(episode, path, options.scale),
        View::FirstPerson => render::first_person(episode, options.size_px),
    };
    let first = draw(&episode, &path);
    let (width, height) = first.dimensions();
    let too_large = || AnimationError::TooLarge { width, height };
    let mut encoder = GifWriter::new(
        Vec::new(),
        u16::try_from(width).map_err(|_| too_large())?,
        u16::try_from(height).map_err(|_| too_large())?,
    )?;
    // Each frame is written when the next one is known, so the last can be held longer.
    let mut pending = first;
    for (k, &action) in actions.iter().enumerate() {
        check_logged_step(&episode, logged, k)?;
        let r = episode.step(action);
        if !r.collided {
            path.push(r.pose.position());
        }
        let step = k + 1;
        if step % stride == 0 || step == actions.len() {
            let frame = draw(&episode, &path);
            encoder.add(&pending, options.frame_delay_cs)?;
            pending = frame;
        }
    }
    encoder.add(&pending, options.last_frame_delay_cs)?;
    let frames = encoder.frames();
    Ok(Animation {
        bytes: encoder.finish()?,
        frames,
        steps: actions.len(),
        size: (width, height),
    })
}

/// Before replaying logged step `k` (from 0) on `episode`: the model's pose must be the logged
/// one (`logged`, when the log has poses), and the episode must still be going.
pub(crate) fn check_logged_step(
    episode: &Episode,
    logged: Option<&[Pose]>,
    k: usize,
) -> Result<(), AnimationError> {
    if let Some(poses) = logged {
        let model = episode.pose();
        if !same_pose(poses[k], model) {
            return Err(AnimationError::Diverged {
                step: k + 1,
                logged: poses[k],
                model,
            });
        }
    }
    if episode.status().is_done() {
        return Err(AnimationError::EndedEarly {
            step: k + 1,
            status: episode.status().name(),
        });
    }
    Ok(())
}

/// Whether two poses agree to a log's precision (headings compared around the circle).
pub(crate) fn same_pose(a: Pose, b: Pose) -> bool {
    let dz = crate::geometry::wrap_deg(a.z_deg - b.z_deg);
    (a.x - b.x).abs() <= POSE_TOLERANCE
        && (a.y - b.y).abs() <= POSE_TOLERANCE
        && dz.min(360.0 - dz) <= POSE_TOLERANCE
}

/// A GIF encoder for pictures in [`render::PALETTE`]'s colours (any other colour becomes the
/// nearest of them). Each frame after the first stores only the rectangle that changed.
pub struct GifWriter<W: Write> {
    encoder: gif::Encoder<W>,
    palette: Vec<image::Rgb<u8>>,
    width: u16,
    height: u16,
    previous: Option<Vec<u8>>,
    frames: usize,
}

impl<W: Write> GifWriter<W> {
    /// An animation of `width` x `height` frames, looping forever.
    pub fn new(out: W, width: u16, height: u16) -> Result<Self, gif::EncodingError> {
        Self::with_palette(out, width, height, &render::PALETTE)
    }

    /// An animation whose pictures use the colours of `palette` (at most 256; any other colour
    /// becomes the nearest of them).
    pub fn with_palette(
        out: W,
        width: u16,
        height: u16,
        palette: &[image::Rgb<u8>],
    ) -> Result<Self, gif::EncodingError> {
        let palette = palette[..palette.len().min(256)].to_vec();
        let bytes: Vec<u8> = palette.iter().flat_map(|c| c.0).collect();
        let mut encoder = gif::Encoder::new(out, width, height, &bytes)?;
        encoder.set_repeat(gif::Repeat::Infinite)?;
        Ok(Self {
            encoder,
            palette,
            width,
            height,
            previous: None,
            frames: 0,
        })
    }

    /// Adds a frame shown for `delay_cs` hundredths of a second. Its size must be the
    /// animation's.
    pub fn add(&mut self, image: &RgbImage, delay_cs: u16) -> Result<(), gif::EncodingError> {
        let (w, h) = (usize::from(self.width), usize::from(self.height));
        if image.dimensions() != (u32::from(self.width), u32::from(self.height)) {
            return Err(gif::EncodingError::from(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "frame of {:?} pixels in an animation of {w} x {h}",
                    image.dimensions()
                ),
            )));
        }
        // Pictures come in long runs of one colour: look each new colour up once.
        let palette = &self.palette;
        let mut last = ([255, 255, 255], palette_index(palette, [255, 255, 255]));
        let indices: Vec<u8> = image
            .pixels()
            .map(|p| {
                if p.0 != last.0 {
                    last = (p.0, palette_index(palette, p.0));
                }
                last.1
            })
            .collect();
        // The rectangle that changed; a frame identical to the last still takes its time, as one
        // unchanged pixel.
        let (x0, y0, x1, y1) = match &self.previous {
            None => (0, 0, w - 1, h - 1),
            Some(before) => changed_rect(before, &indices, w).unwrap_or((0, 0, 0, 0)),
        };
        let mut buffer = Vec::with_capacity((x1 - x0 + 1) * (y1 - y0 + 1));
        for row in y0..=y1 {
            buffer.extend_from_slice(&indices[row * w + x0..=row * w + x1]);
        }
        // The rectangle lies inside a frame whose sides fit in u16, so these conversions hold.
        let frame = gif::Frame {
            delay: delay_cs,
            dispose: gif::DisposalMethod::Keep,
            left: x0 as u16,
            top: y0 as u16,
            width: (x1 - x0 + 1) as u16,
            height: (y1 - y0 + 1) as u16,
            buffer: std::borrow::Cow::Owned(buffer),
            ..gif::Frame::default()
        };
        self.encoder.write_frame(&frame)?;
        self.previous = Some(indices);
        self.frames += 1;
        Ok(())
    }

    /// Frames added so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Ends the file and returns the writer.
    pub fn finish(self) -> Result<W, gif::EncodingError> {
        Ok(self.encoder.into_inner()?)
    }
}

/// The index in `palette` of `rgb`, or of the nearest colour there.
fn palette_index(palette: &[image::Rgb<u8>], rgb: [u8; 3]) -> u8 {
    let distance = |c: &image::Rgb<u8>| {
        c.0.iter()
            .zip(rgb)
            .map(|(&a, b)| (i32::from(a) - i32::from(b)).pow(2))
            .sum::<i32>()
    };
    palette
        .iter()
        .enumerate()
        .min_by_key(|(_, c)| distance(c))
        .map_or(0, |(i, _)| i as u8)
}

/// The smallest rectangle `(x0, y0, x1, y1)` (inclusive) holding every pixel that differs between
/// `a` and `b`, rows of `width`; `None` when they are equal.
fn changed_rect(a: &[u8], b: &[u8], width: usize) -> Option<(usize, usize, usize, usize)> {
    let mut rect: Option<(usize, usize, usize, usize)> = None;
    for (row, (ra, rb)) in a.chunks(width).zip(b.chunks(width)).enumerate() {
        let Some(first) = ra.iter().zip(rb).position(|(x, y)| x != y) else {
            continue;
        };
        let last = ra
            .iter()
            .zip(rb)
            .rposition(|(x, y)| x != y)
            .unwrap_or(first);
        rect = Some(match rect {
            None => (first, row, last, row),
            Some((x0, y0, x1, _)) => (x0.min(first), y0, x1.max(last), row),
        });
    }
    rect
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::ValidConfig;
    use crate::sim::{maze_scene, DiscreteAction};
    use std::sync::Arc;

    fn episode(seed: u64) -> Episode {
        let config = ValidConfig::default();
        let scene = Arc::new(maze_scene(&config, seed));
        Episode::new(&config, scene, seed).expect("default scene places")
    }

    fn decode(bytes: &[u8]) -> Vec<RgbImage> {
        use image::AnimationDecoder;
        let decoder = image::codecs::gif::GifDecoder::new(std::io::Cursor::new(bytes)).unwrap();
        decoder
            .into_frames()
            .map(|f| image::DynamicImage::ImageRgba8(f.unwrap().into_buffer()).to_rgb8())
            .collect()
    }

    #[test]
    fn frames_follow_the_stride_and_show_the_model_exactly() {
        let actions: Vec<Action> = [DiscreteAction::Left, DiscreteAction::Ahead]
            .iter()
            .cycle()
            .take(7)
            .map(|&a| a.into())
            .collect();
        let options = GifOptions {
            stride: 3,
            scale: 0.2,
            ..GifOptions::default()
        };
        let a = animate(episode(3), &actions, None, &options).unwrap();
        // States 0, 3, 6 and the last, 7.
        assert_eq!(a.frames, 4);
        let frames = decode(&a.bytes);
        assert_eq!(frames.len(), 4);
        assert_eq!(frames[0].dimensions(), (200, 200));
        // The decoded last frame is the picture of the last state, pixel for pixel.
        let mut e = episode(3);
        let mut path = vec![e.pose().position()];
        for &action in &actions {
            let r = e.step(action);
            if !r.collided {
                path.push(r.pose.position());
            }
        }
        assert_eq!(frames[3], render::top_down(&e, &path, 0.2));
        assert_ne!(frames[0], frames[3]);
    }

    #[test]
    fn a_log_from_elsewhere_is_named_by_its_step() {
        let actions = vec![Action::from(DiscreteAction::Ahead); 3];
        let mut e = episode(5);
        let mut poses = vec![];
        for &a in &actions {
            poses.push(e.pose());
            e.step(a);
        }
        let options = GifOptions::default();
        assert!(animate(episode(5), &actions, Some(&poses), &options).is_ok());
        poses[2].x += 1.0;
        let err = animate(episode(5), &actions, Some(&poses), &options).unwrap_err();
        assert!(
            matches!(err, AnimationError::Diverged { step: 3, .. }),
            "{err}"
        );
        assert!(err
            .to_string()
            .starts_with("step 3: the log has the robot at"));
    }

    #[test]
    fn unchanged_frames_are_one_pixel_and_colours_are_exact() {
        let mut img = RgbImage::from_pixel(4, 3, render::FLOOR);
        let mut w = GifWriter::new(Vec::new(), 4, 3).unwrap();
        w.add(&img, 5).unwrap();
        w.add(&img, 5).unwrap();
        img.put_pixel(2, 1, render::GOAL);
        img.put_pixel(1, 2, image::Rgb([30, 160, 70]));
        w.add(&img, 5).unwrap();
        let frames = decode(&w.finish().unwrap());
        assert_eq!(frames.len(), 3);
        assert_eq!(*frames[2].get_pixel(2, 1), render::GOAL);
        // An off-palette colour becomes the nearest palette colour.
        assert_eq!(*frames[2].get_pixel(1, 2), render::GOAL);
        assert_eq!(*frames[1].get_pixel(2, 1), render::FLOOR);
        assert_eq!(
            changed_rect(&[0, 0, 0, 0, 1, 0], &[0, 0, 0, 0, 1, 0], 3),
            None
        );
        assert_eq!(
            changed_rect(&[0, 0, 0, 0, 1, 0], &[0, 2, 0, 0, 1, 3], 3),
            Some((1, 0, 2, 1))
        );
    }
}
