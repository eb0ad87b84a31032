//! Scenes, above `geometry`: the obstacles of a scene, generated mazes, image and ROS maps, and the
//! free-space grid of where a robot fits. Uses `config` and `geometry`.
//!
//! Scenes: the obstacles a robot moves among, as axis-aligned boxes, and the exact queries on them.
//!
//! A scene covers `[0, width] x [0, height]` px. It comes from a generated maze (walls on cell
//! edges), an image (occupied pixels merged into boxes, everything outside the image an obstacle)
//! or boxes given by hand. Queries near a point run through a `BinIndex` so one costs a single
//! bin lookup; rays walk a coarse `RayGrid` so one costs per cell it crosses, whatever its range.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

mod freespace;
pub(crate) mod map;
mod maze;
mod maze_rays;
mod warehouse;

pub use freespace::FreeGrid;
pub use map::{MapError, MapSource, RosMap};
pub use maze::Maze;

// For the layers above only.
pub(crate) use warehouse::Warehouse;

use crate::config::{MapConfig, MazeConfig};
use crate::geometry::prefetch;
use crate::geometry::{Aabb, BinIndex, GridStart, Obstacles, Point, RayGrid, Shape, Vector, V2};
use crate::scene::maze_rays::MazeRays;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Bin side of the query index, px. A bin lists every box within reach of any of its points, so
/// its list grows only slowly with the side (the laser's 50 px reach dominates), while the index's
/// size and build time fall with its square: at 30 px a maze's index is a fifth of its size at
/// 10 px, a reset costs 18 us instead of 50 us, and 1024 environments' indices stay nearer the
/// cache, with the same instruction count per step (callgrind).
const BIN_PX: f64 = 30.0;

/// A scene that could not be built.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The image file could not be read or decoded.
    #[error("cannot read map image {}: {message}", path.display())]
    ImageRead {
        /// The file.
        path: PathBuf,
        /// What the decoder said.
        message: String,
    },
    /// The image has more pixels than ronap reads.
    #[error(
        "map image {} is {width} x {height} pixels, over the {} megapixels ronap reads: scale it \
         down and raise map.resolution_px (scene px per pixel)",
        path.display(),
        MAX_IMAGE_PIXELS >> 20
    )]
    ImageTooLarge {
        /// The file.
        path: PathBuf,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// The image's obstacles are too many separate pieces.
    #[error(
        "map image {} has {runs} runs of obstacle pixels, over the {} ronap reads (a dithered \
         or noisy image?): clean it, or change map.threshold",
        path.display(),
        MAX_IMAGE_RUNS
    )]
    ImageTooBusy {
        /// The file.
        path: PathBuf,
        /// Runs of obstacle pixels along its rows.
        runs: usize,
    },
    /// The image has no pixels.
    #[error("map image {} is empty ({width} x {height} pixels)", path.display())]
    EmptyImage {
        /// The file.
        path: PathBuf,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
}

/// Where a scene came from.
#[derive(Clone, Debug)]
pub enum SceneSource {
    /// A generated maze with cells of `cell_px`.
    Maze {
        /// The maze.
        maze: Maze,
        /// Cell side, px.
        cell_px: f64,
        /// Wall thickness, px.
        wall_thickness_px: f64,
    },
    /// An image, `resolution_px` scene px per pixel.
    Image {
        /// Image width and height, pixels.
        size: (u32, u32),
        /// Scene px per pixel.
        resolution_px: f64,
    },
    /// Boxes given directly.
    Boxes,
}

/// Largest map image read, in pixels (64 megapixels, 8192 x 8192): a scene costs tens of bytes
/// per pixel, and a few bytes of a compressed file can claim any size.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// Most runs of obstacle pixels along the rows (about the boxes a scene is built of) a map image
/// may hold: a scene costs some hundreds of bytes a box, and a dithered or noisy image can hold a
/// box for every other pixel.
pub const MAX_IMAGE_RUNS: usize = 1 << 20;

/// Refuses an occupancy raster of `width` columns (from the image at `path`) whose obstacles are
/// more than [`MAX_IMAGE_RUNS`] runs of pixels.
pub fn check_runs(occupied: &[bool], width: u32, path: &Path) -> Result<(), SceneError> {
    let width = (width as usize).max(1);
    let runs: usize = occupied
        .chunks(width)
        .map(|row| {
            row.iter()
                .zip(std::iter::once(&false).chain(row.iter()))
                .filter(|(&now, &before)| now && !before)
                .count()
        })
        .sum();
    if runs > MAX_IMAGE_RUNS {
        return Err(SceneError::ImageTooBusy {
            path: path.to_path_buf(),
            runs,
        });
    }
    Ok(())
}

/// Width, height and the occupancy raster of `image` (image order): grey value <= `threshold`
/// is an obstacle.
fn occupancy(image: &image::DynamicImage, threshold: u8) -> (u32, u32, Vec<bool>) {
    let grey = image.to_luma8();
    let occupied = grey.pixels().map(|p| p.0[0] <= threshold).collect();
    (grey.width(), grey.height(), occupied)
}

/// Reads and decodes an image file (PNG, PGM, or any format the decoder recognises), refusing
/// an empty one and one over [`MAX_IMAGE_PIXELS`].
pub fn read_image(path: &Path) -> Result<image::DynamicImage, SceneError> {
    let reader = image::ImageReader::open(path).map_err(|e| SceneError::ImageRead {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    decode_image(reader, path)
}

/// Decodes the image of `bytes` ([`read_image`]); `path` names it in errors.
pub fn decode_image_bytes(bytes: &[u8], path: &Path) -> Result<image::DynamicImage, SceneError> {
    decode_image(image::ImageReader::new(std::io::Cursor::new(bytes)), path)
}

fn decode_image<R: std::io::BufRead + std::io::Seek>(
    reader: image::ImageReader<R>,
    path: &Path,
) -> Result<image::DynamicImage, SceneError> {
    let read_error = |message: String| SceneError::ImageRead {
        path: path.to_path_buf(),
        message,
    };
    let mut reader = reader
        .with_guessed_format()
        .map_err(|e| read_error(e.to_string()))?;
    let mut limits = image::Limits::default();
    // Eight bytes a pixel: the widest pixels (RGBA of 16 bits) of the largest image read.
    limits.max_alloc = Some(MAX_IMAGE_PIXELS * 8);
    reader.limits(limits);
    let decoder = reader
        .into_decoder()
        .map_err(|e| read_error(e.to_string()))?;
    let (width, height) = image::ImageDecoder::dimensions(&decoder);
    if u64::from(width) * u64::from(height) > MAX_IMAGE_PIXELS {
        return Err(SceneError::ImageTooLarge {
            path: path.to_path_buf(),
            width,
            height,
        });
    }
    let image =
        image::DynamicImage::from_decoder(decoder).map_err(|e| read_error(e.to_string()))?;
    if image.width() == 0 || image.height() == 0 {
        return Err(SceneError::EmptyImage {
            path: path.to_path_buf(),
            width: image.width(),
            height: image.height(),
        });
    }
    Ok(image)
}

/// How a scene's long rays find the boxes they cross.
#[derive(Clone, Debug)]
enum RayIndex {
    /// A maze's own walls: the cells and the wall on each edge.
    Maze(MazeRays),
    /// Any boxes: a uniform grid listing the boxes touching each cell.
    Grid(RayGrid),
}

/// Rays from one point of a scene ([`Scene::rays_from`]).
#[derive(Clone, Copy, Debug)]
pub struct RaysFrom<'a> {
    start: RayStart<'a>,
}

/// Where rays from one point start, in the scene's [`RayIndex`].
#[derive(Clone, Copy, Debug)]
enum RayStart<'a> {
    Maze(&'a MazeRays, maze_rays::Start),
    Grid(&'a RayGrid, GridStart),
}

impl RaysFrom<'_> {
    /// For each beam, its direction (a unit vector) and where to write its reading: the nearest
    /// hit among the scene's boxes within `max_px` ([`RaysFrom::first_box_hit`]), else `max_px`.
    /// The same as asking beam by beam, with what the beams share worked out once.
    ///
    /// The walks run compiled for the widest instruction set the processor has, AVX-512
    /// included (see `geometry::WIDEST`); the same bits.
    #[inline]
    pub fn first_box_hits<'b>(
        &self,
        max_px: f64,
        beams: impl Iterator<Item = (Vector, &'b mut f64)>,
    ) {
        crate::geometry::WIDEST.dispatch(FirstBoxHits {
            start: &self.start,
            max_px,
            beams,
        });
    }

    /// The nearest [`Aabb::ray_hit`] among the scene's boxes (not its shapes) of the ray along the
    /// unit direction `dir`, within `max_px`, with `1 / dir` per component as the inverse
    /// direction: exactly the least over every box. Costs per coarse cell the ray crosses before
    /// its first hit, whatever `max_px`.
    #[inline]
    pub fn first_box_hit(&self, dir: Vector, max_px: f64) -> Option<f64> {
        let inv = inverse(dir);
        match &self.start {
            RayStart::Maze(walls, start) => walls.cast(start, dir, inv, max_px),
            RayStart::Grid(grid, start) => grid.cast(start, dir, inv, max_px),
        }
    }
}

/// `1 / dir` per component.
#[inline(always)]
fn inverse(dir: Vector) -> Vector {
    Vector::new(1.0 / dir.x, 1.0 / dir.y)
}

/// [`RaysFrom::first_box_hits`] as pulp runs it, compiled once per instruction set.
struct FirstBoxHits<'a, I> {
    start: &'a RayStart<'a>,
    max_px: f64,
    beams: I,
}

impl<'b, I: Iterator<Item = (Vector, &'b mut f64)>> pulp::WithSimd for FirstBoxHits<'_, I> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        let max_px = self.max_px;
        match self.start {
            RayStart::Maze(walls, start) => {
                for (dir, reading) in self.beams {
                    *reading = walls
                        .cast(start, dir, inverse(dir), max_px)
                        .unwrap_or(max_px);
                }
            }
            RayStart::Grid(grid, start) => {
                for (dir, reading) in self.beams {
                    *reading = grid
                        .cast(start, dir, inverse(dir), max_px)
                        .unwrap_or(max_px);
                }
            }
        }
    }
}

/// Obstacles and the queries the sensors and collision checks need.
#[derive(Clone, Debug)]
pub struct Scene {
    width: f64,
    height: f64,
    boxes: Vec<Aabb>,
    index: BinIndex,
    /// How long rays find the boxes they cross, built on the first ray that needs it.
    rays: OnceLock<RayIndex>,
    source: SceneSource,
    /// Discs and convex polygons, checked one by one (a scene has few).
    shapes: Vec<Shape>,
    /// Whether obstacles were added to the generated or loaded scene.
    added: bool,
}

impl Scene {
    /// A scene of `width x height` px with the given obstacle boxes. `reach_px` is the longest
    /// query distance to make fast (the laser range, or a step plus the robot radius); longer
    /// queries stay exact but read every box.
    pub fn from_boxes(width: f64, height: f64, boxes: Vec<Aabb>, reach_px: f64) -> Self {
        Self::build(width, height, boxes, reach_px, SceneSource::Boxes)
    }

    fn build(
        width: f64,
        height: f64,
        boxes: Vec<Aabb>,
        reach_px: f64,
        source: SceneSource,
    ) -> Self {
        let bounds = Aabb::from_corners(Point::origin(), Point::new(width, height));
        let index = BinIndex::new(&boxes, bounds, reach_px, BIN_PX);
        Self {
            width,
            height,
            boxes,
            index,
            rays: OnceLock::new(),
            source,
            shapes: Vec::new(),
            added: false,
        }
    }

    /// This scene with `boxes` (kept in the fast index) and `shapes` added to its obstacles.
    pub fn with_obstacles(self, boxes: Vec<Aabb>, shapes: Vec<Shape>) -> Self {
        if boxes.is_empty() && shapes.is_empty() {
            return self;
        }
        let mut scene = if boxes.is_empty() {
            self
        } else {
            let mut all = self.boxes;
            all.extend(boxes);
            let mut s = Self::build(
                self.width,
                self.height,
                all,
                self.index.reach_px(),
                self.source,
            );
            s.shapes = self.shapes;
            s
        };
        scene.shapes.extend(shapes);
        scene.added = true;
        scene
    }

    /// The discs and convex polygons among the obstacles.
    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }

    /// Whether obstacles were added to the generated or loaded scene (so a maze is no longer one
    /// free region by construction).
    pub fn has_added_obstacles(&self) -> bool {
        self.added
    }

    /// The scene of a maze, with walls as `config` says.
    pub fn from_maze(maze: Maze, config: &MazeConfig, reach_px: f64) -> Self {
        let boxes = maze.wall_boxes(config.cell_px, config.wall_thickness_px);
        let width = maze.cols() as f64 * config.cell_px;
        let height = maze.rows() as f64 * config.cell_px;
        let source = SceneSource::Maze {
            maze,
            cell_px: config.cell_px,
            wall_thickness_px: config.wall_thickness_px,
        };
        Self::build(width, height, boxes, reach_px, source)
    }

    /// A scene from an occupancy raster, `occupied[row * width + col]` with row 0 at the **top**
    /// (image order). Each pixel is a `resolution_px` square; everything outside is an obstacle.
    pub fn from_occupancy(
        width: u32,
        height: u32,
        occupied: &[bool],
        resolution_px: f64,
        reach_px: f64,
    ) -> Self {
        let (w, h) = (width as usize, height as usize);
        assert_eq!(occupied.len(), w * h, "occupancy raster size");
        let res = resolution_px;
        let mut boxes = Vec::new();
        // Runs of occupied pixels per row, merged downwards while the next row has the same run.
        // `open` holds (x0, x1, top row) of runs still growing, sorted by x0.
        let mut open: Vec<(usize, usize, usize)> = Vec::new();
        let mut next: Vec<(usize, usize, usize)> = Vec::new();
        let close = |(x0, x1, top): (usize, usize, usize), bottom: usize, boxes: &mut Vec<Aabb>| {
            // Rows top..bottom (exclusive) in image order span y from (h - bottom) to (h - top).
            boxes.push(Aabb::from_corners(
                Point::new(x0 as f64 * res, (h - bottom) as f64 * res),
                Point::new(x1 as f64 * res, (h - top) as f64 * res),
            ));
        };
        for row in 0..=h {
            next.clear();
            let mut k = 0;
            let mut col = 0;
            while row < h && col < w {
                if !occupied[row * w + col] {
                    col += 1;
                    continue;
                }
                let x0 = col;
                while col < w && occupied[row * w + col] {
                    col += 1;
                }
                let x1 = col;
                while k < open.len() && open[k].0 < x0 {
                    close(open[k], row, &mut boxes);
                    k += 1;
                }
                if k < open.len() && open[k].0 == x0 && open[k].1 == x1 {
                    next.push(open[k]);
                    k += 1;
                } else {
                    next.push((x0, x1, row));
                }
            }
            for &run in &open[k..] {
                close(run, row, &mut boxes);
            }
            std::mem::swap(&mut open, &mut next);
        }
        let (sw, sh) = (w as f64 * res, h as f64 * res);
        // Outside the image is an obstacle: a frame deep enough that no query sees past it.
        let t = reach_px + res + 1.0;
        boxes.push(Aabb::from_corners(
            Point::new(-t, -t),
            Point::new(0.0, sh + t),
        ));
        boxes.push(Aabb::from_corners(
            Point::new(sw, -t),
            Point::new(sw + t, sh + t),
        ));
        boxes.push(Aabb::from_corners(Point::new(0.0, -t), Point::new(sw, 0.0)));
        boxes.push(Aabb::from_corners(
            Point::new(0.0, sh),
            Point::new(sw, sh + t),
        ));
        let source = SceneSource::Image {
            size: (width, height),
            resolution_px,
        };
        Self::build(sw, sh, boxes, reach_px, source)
    }

    /// A scene from a decoded image: grey value <= `threshold` is an obstacle.
    pub fn from_image(image: &image::DynamicImage, config: &MapConfig, reach_px: f64) -> Self {
        let (width, height, occupied) = occupancy(image, config.threshold);
        Self::from_occupancy(width, height, &occupied, config.resolution_px, reach_px)
    }

    /// Reads a PNG or PGM file (any format the decoder knows) as a scene.
    pub fn load_image(path: &Path, config: &MapConfig, reach_px: f64) -> Result<Self, SceneError> {
        Self::from_user_image(&read_image(path)?, config, reach_px, path)
    }

    /// Like [`Scene::from_image`], for an image a user gave as `path`: refused, naming it, if its
    /// obstacles are more than [`MAX_IMAGE_RUNS`] runs of pixels.
    pub fn from_user_image(
        image: &image::DynamicImage,
        config: &MapConfig,
        reach_px: f64,
        path: &Path,
    ) -> Result<Self, SceneError> {
        let (width, height, occupied) = occupancy(image, config.threshold);
        check_runs(&occupied, width, path)?;
        Ok(Self::from_occupancy(
            width,
            height,
            &occupied,
            config.resolution_px,
            reach_px,
        ))
    }

    /// Width, px.
    pub fn width(&self) -> f64 {
        self.width
    }

    /// Height, px.
    pub fn height(&self) -> f64 {
        self.height
    }

    /// `[0, width] x [0, height]`.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_corners(Point::origin(), Point::new(self.width, self.height))
    }

    /// The obstacle boxes.
    pub fn boxes(&self) -> &[Aabb] {
        &self.boxes
    }

    /// Where the scene came from.
    pub fn source(&self) -> &SceneSource {
        &self.source
    }

    /// The maze, for maze scenes.
    pub fn maze(&self) -> Option<(&Maze, f64)> {
        match &self.source {
            SceneSource::Maze { maze, cell_px, .. } => Some((maze, *cell_px)),
            _ => None,
        }
    }

    /// Indices of the boxes within `radius` of `p` (and possibly a few further).
    #[inline]
    pub fn boxes_near(&self, p: Point, radius: f64) -> &[u32] {
        self.index.near(p, radius)
    }

    /// The still obstacles within `reach` of `p` as ORCA avoids them, into `out` (cleared
    /// first): boxes as rectangles, added discs as the 12-gons round them, polygons as they are,
    /// each counter-clockwise.
    pub fn orca_obstacles_near(&self, p: Point, reach: f64, out: &mut Obstacles<f64>) {
        /// Sides of the polygon round a disc.
        const DISC_SIDES: usize = 12;
        out.vertices.clear();
        let mut add_box = |b: &Aabb| {
            let (lo, hi) = (b.min, b.max);
            out.add(&[
                V2::new(lo.x, lo.y),
                V2::new(hi.x, lo.y),
                V2::new(hi.x, hi.y),
                V2::new(lo.x, hi.y),
            ]);
        };
        if self.piece_px(reach).is_some() {
            for &b in self.boxes_near(p, reach) {
                add_box(&self.boxes[b as usize]);
            }
        } else {
            // Beyond the index's reach: every box near enough.
            for b in self
                .boxes
                .iter()
                .filter(|b| b.distance_squared(p) <= reach * reach)
            {
                add_box(b);
            }
        }
        for shape in &self.shapes {
            if shape.aabb().distance_squared(p) > reach * reach {
                continue;
            }
            let corners: Vec<V2<f64>> = match shape.as_disc() {
                Some((c, r)) => {
                    let step = std::f64::consts::TAU / DISC_SIDES as f64;
                    let out_r = r / (step / 2.0).cos();
                    (0..DISC_SIDES)
                        .map(|j| {
                            let a = step * j as f64;
                            V2::new(c.x + out_r * a.cos(), c.y + out_r * a.sin())
                        })
                        .collect()
                }
                None => shape
                    .corners()
                    .into_iter()
                    .map(|c| V2::new(c.x, c.y))
                    .collect(),
            };
            out.add(&corners);
        }
    }

    /// Calls `f` with the nearest point of every still obstacle (box, disc or polygon) that
    /// lies within `reach` of `p`, in no particular order.
    pub fn nearest_points(&self, p: Point, reach: f64, mut f: impl FnMut(Point)) {
        let reach2 = reach * reach;
        let mut boxes = |b: &Aabb| {
            if b.distance_squared(p) <= reach2 {
                f(b.nearest_point(p));
            }
        };
        if self.piece_px(reach).is_some() {
            for &b in self.boxes_near(p, reach) {
                boxes(&self.boxes[b as usize]);
            }
        } else {
            self.boxes.iter().for_each(boxes);
        }
        for shape in &self.shapes {
            if shape.aabb().distance_squared(p) <= reach2 {
                let q = shape.nearest_point(p);
                if (q - p).norm_squared() <= reach2 {
                    f(q);
                }
            }
        }
    }

    /// Length of the pieces long queries are cut into, so that each piece (grown by `radius`) is
    /// answered by one bin of the index; `None` when the index cannot serve `radius` at all.
    fn piece_px(&self, radius: f64) -> Option<f64> {
        let piece = self.index.reach_px() - radius;
        (piece >= 1.0).then_some(piece)
    }

    /// What long rays walk: a maze's own cells and walls, or for other scenes (and mazes with
    /// added boxes) a uniform grid sized to their boxes.
    fn ray_index(&self) -> &RayIndex {
        self.rays.get_or_init(|| {
            if let SceneSource::Maze {
                maze,
                cell_px,
                wall_thickness_px,
            } = &self.source
            {
                let walls = MazeRays::new(maze, *cell_px, *wall_thickness_px);
                if let Some(walls) = walls.filter(|w| w.boxes() == self.boxes.as_slice()) {
                    return RayIndex::Maze(walls);
                }
            }
            RayIndex::Grid(RayGrid::fitted(&self.boxes, self.bounds()))
        })
    }

    /// Rays from `origin`, which share the work of finding where they start (a scan's beams).
    #[inline]
    pub fn rays_from(&self, origin: Point) -> RaysFrom<'_> {
        let start = match self.ray_index() {
            RayIndex::Maze(walls) => RayStart::Maze(walls, walls.start(origin)),
            RayIndex::Grid(grid) => RayStart::Grid(grid, grid.start(origin)),
        };
        RaysFrom { start }
    }

    /// The nearest [`Aabb::ray_hit`] among the boxes (not the shapes) of the ray from `origin`
    /// along the unit direction `dir`, within `max_px` ([`RaysFrom::first_box_hit`]).
    pub fn first_box_hit(&self, origin: Point, dir: Vector, max_px: f64) -> Option<f64> {
        self.rays_from(origin).first_box_hit(dir, max_px)
    }

    /// Distance from `origin` along the unit direction `dir` to the first obstacle, if one lies
    /// within `max_px`. `Some(0.0)` when `origin` is inside an obstacle.
    pub fn cast_ray(&self, origin: Point, dir: Vector, max_px: f64) -> Option<f64> {
        let boxes = self.first_box_hit(origin, dir, max_px);
        if self.shapes.is_empty() {
            return boxes;
        }
        let best = self
            .shapes
            .iter()
            .filter_map(|s| s.cast_ray(origin, dir, max_px))
            .fold(boxes.unwrap_or(f64::INFINITY), f64::min);
        best.is_finite().then_some(best)
    }

    /// Asks for the memory the queries about `p` read, one link of the chain a call (`stage`
    /// 0, 1, then 2: the bin, its list, its boxes). Results never change.
    pub(crate) fn prefetch_near(&self, p: Point, stage: usize) {
        self.index.prefetch_near(p, stage, |i| {
            if let Some(b) = self.boxes.get(i as usize) {
                prefetch::line(&b.min);
                prefetch::line(&b.max);
            }
        });
    }

    /// Whether a disc of `radius` at `p` touches no obstacle (a tangent disc does not touch).
    pub fn disc_clear(&self, p: Point, radius: f64) -> bool {
        let r2 = radius * radius;
        self.index
            .near(p, radius)
            .iter()
            .all(|&i| self.boxes[i as usize].distance_squared(p) >= r2)
            && self.shapes.iter().all(|s| s.distance(p) >= radius)
    }

    /// Whether a disc of `radius` can move in a straight line from `a` to `b` touching nothing:
    /// the whole swept capsule is checked, so no step length passes through an obstacle.
    pub fn sweep_clear(&self, a: Point, b: Point, radius: f64) -> bool {
        let piece_clear = |a: Point, b: Point| {
            let reach = (b - a).norm() + radius;
            // A box at least `reach` from `a` is at least `radius` from every point of the
            // piece: the cheap test settles most of the bin's list.
            let far2 = reach * reach;
            self.index.near(a, reach).iter().all(|&i| {
                let b_ = &self.boxes[i as usize];
                b_.distance_squared(a) >= far2 || b_.segment_clear(a, b, radius)
            })
        };
        // A shape whose bounding box lies further from `a` than the sweep's length and radius
        // (with room for rounding) is clear of it without measuring: among many walkers, most
        // are far from every pillar.
        let length = (b - a).norm();
        // The margin grows with the coordinates too: their rounding does.
        let far = (length + radius) * (1.0 + 1e-9) + 1e-9 * (a.x.abs().max(a.y.abs()) + 1.0);
        if !self
            .shapes
            .iter()
            .all(|s| s.aabb().distance_squared(a) > far * far || s.segment_distance(a, b) >= radius)
        {
            return false;
        }
        let Some(piece) = self.piece_px(radius).filter(|&p| length > p) else {
            return piece_clear(a, b);
        };
        let pieces = (length / piece).ceil() as usize;
        (0..pieces).all(|k| {
            let from = a + (b - a) * (k as f64 / pieces as f64);
            let to = a + (b - a) * ((k + 1) as f64 / pieces as f64);
            piece_clear(from, to)
        })
    }

    /// Whether the box `b` lies inside the scene and overlaps no obstacle (touching is allowed).
    pub fn box_clear(&self, b: Aabb) -> bool {
        let inside = self.bounds();
        if !(inside.contains(b.min) && inside.contains(b.max)) {
            return false;
        }
        let half = b.extents() / 2.0;
        let center = b.min + half;
        let overlaps = |o: &Aabb| {
            o.min.x < b.max.x && b.min.x < o.max.x && o.min.y < b.max.y && b.min.y < o.max.y
        };
        !self
            .index
            .near(center, half.norm())
            .iter()
            .any(|&i| overlaps(&self.boxes[i as usize]))
            && self
                .shapes
                .iter()
                .all(|s| s.hull_distance(&b.corners()) > 0.0)
    }

    /// Whether an axis-aligned box of half extents `half` can move its centre in a straight line
    /// from `a` to `b`, ending inside the scene, without overlapping an obstacle.
    pub fn box_sweep_clear(&self, a: Point, b: Point, half: Vector) -> bool {
        let end = Aabb::from_corners(b - half, b + half);
        let inside = self.bounds();
        if !(inside.contains(end.min) && inside.contains(end.max)) {
            return false;
        }
        // The box against each obstacle box is its centre against the obstacle grown by `half`.
        let reach = (b - a).norm() + half.norm();
        let boxes_clear = self.index.near(a, reach).iter().all(|&i| {
            let o = self.boxes[i as usize];
            let grown = Aabb {
                min: o.min - half,
                max: o.max + half,
            };
            grown.segment_distance_squared(a, b) > 0.0
        });
        boxes_clear
            && (self.shapes.is_empty() || {
                let corners: Vec<Point> = [a, b]
                    .iter()
                    .flat_map(|&c| {
                        [
                            c - half,
                            c + Vector::new(half.x, -half.y),
                            c + half,
                            c + Vector::new(-half.x, half.y),
                        ]
                    })
                    .collect();
                self.shapes.iter().all(|s| s.hull_distance(&corners) > 0.0)
            })
    }

    /// A box round `p`, inside the scene, whose interior no obstacle enters (obstacles may touch
    /// its sides): anything strictly inside it is clear, without a further query. Grown from `p`
    /// along x first, then y (or y first with `y_first`), so a corridor gives a box as long as
    /// the reach allows. A point box when `p` is in an obstacle.
    ///
    /// For something at `p` heading along `dir` (a unit vector, or zero), the box is sought
    /// within the index's reach of `p + dir * reach / 2` (of `p` itself when `dir` is zero), so
    /// it still holds `p` and reaches half as far again ahead (and half as far behind).
    pub fn free_box_toward(&self, p: Point, y_first: bool, dir: Vector) -> Aabb {
        let reach = self.index.reach_px();
        let point = Aabb { min: p, max: p };
        if !self.bounds().contains(p) {
            return point;
        }
        let lead = reach / 2.0;
        let c = Point::new(
            (p.x + dir.x.clamp(-1.0, 1.0) * lead).clamp(0.0, self.width),
            (p.y + dir.y.clamp(-1.0, 1.0) * lead).clamp(0.0, self.height),
        );
        let cap = Aabb {
            min: Point::new((c.x - reach).max(0.0), (c.y - reach).max(0.0)),
            max: Point::new(
                (c.x + reach).min(self.width),
                (c.y + reach).min(self.height),
            ),
        };
        // Shapes by their bounding boxes: the box stays clear, if smaller than it could be.
        let near = self
            .index
            .near(c, reach)
            .iter()
            .map(|&i| self.boxes[i as usize]);
        let obstacles = near.chain(self.shapes.iter().map(Shape::aabb));
        let mut free = point;
        // Two passes: the first axis grows across the point, the second across that span.
        for (pass, axis) in [usize::from(y_first), usize::from(!y_first)]
            .into_iter()
            .enumerate()
        {
            let other = 1 - axis;
            let (mut lo, mut hi) = (cap.min[axis], cap.max[axis]);
            for o in obstacles.clone() {
                // Only obstacles across the span of the other axis bound it: across the point
                // itself (touching counts) in the first pass, across the open span in the second.
                let apart = if pass == 0 {
                    o.min[other] > free.max[other] || o.max[other] < free.min[other]
                } else {
                    o.min[other] >= free.max[other] || o.max[other] <= free.min[other]
                };
                if apart {
                    continue;
                }
                if o.max[axis] <= free.min[axis] {
                    lo = lo.max(o.max[axis]);
                } else if o.min[axis] >= free.max[axis] {
                    hi = hi.min(o.min[axis]);
                } else {
                    // It overlaps what is already free, so `p` is on an obstacle.
                    return point;
                }
            }
            free.min[axis] = lo;
            free.max[axis] = hi;
        }
        free
    }

    /// Whether `p` lies inside an obstacle or outside the scene.
    pub fn occupied(&self, p: Point) -> bool {
        !self.bounds().contains(p)
            || self
                .index
                .near(p, 0.0)
                .iter()
                .any(|&i| self.boxes[i as usize].contains(p))
            || self.shapes.iter().any(|s| s.distance(p) == 0.0)
    }

    /// Distance from `p` to the nearest obstacle, if one lies within `max_px`.
    pub fn clearance(&self, p: Point, max_px: f64) -> Option<f64> {
        let d2 = self
            .index
            .near(p, max_px)
            .iter()
            .map(|&i| self.boxes[i as usize].distance_squared(p))
            .fold(f64::INFINITY, f64::min);
        let d = self
            .shapes
            .iter()
            .map(|s| s.distance(p))
            .fold(d2.sqrt(), f64::min);
        (d <= max_px).then_some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::unit;

    fn square_room() -> Scene {
        let occupied = vec![false; 100 * 80];
        Scene::from_occupancy(100, 80, &occupied, 1.0, 50.0)
    }

    #[test]
    fn outside_an_image_is_an_obstacle() {
        let room = square_room();
        let p = Point::new(30.0, 40.0);
        assert_eq!(room.cast_ray(p, unit(180.0), 50.0), Some(30.0));
        assert_eq!(room.cast_ray(p, unit(0.0), 50.0), None);
        assert!(room.occupied(Point::new(-0.5, 10.0)));
        assert!(!room.occupied(p));
    }

    #[test]
    fn occupancy_runs_merge_into_boxes() {
        // A 4 x 3 image with a 2-wide column block at x 1..3 on rows 0..2 (top two rows).
        #[rustfmt::skip]
        let occupied = [
            false, true, true, false,
            false, true, true, false,
            false, false, false, true,
        ];
        let scene = Scene::from_occupancy(4, 3, &occupied, 10.0, 5.0);
        let inner: Vec<_> = scene.boxes()[..scene.boxes().len() - 4].to_vec();
        assert_eq!(
            inner,
            vec![
                Aabb::from_corners(Point::new(10.0, 10.0), Point::new(30.0, 30.0)),
                Aabb::from_corners(Point::new(30.0, 0.0), Point::new(40.0, 10.0)),
            ]
        );
    }

    #[test]
    fn sweep_catches_a_thin_wall_at_any_speed() {
        let wall = Aabb::from_corners(Point::new(99.0, 0.0), Point::new(101.0, 200.0));
        let scene = Scene::from_boxes(200.0, 200.0, vec![wall], 55.0);
        let a = Point::new(50.0, 100.0);
        assert!(!scene.sweep_clear(a, Point::new(150.0, 100.0), 5.0));
        assert!(!scene.sweep_clear(a, Point::new(1050.0, 100.0), 5.0));
        assert!(scene.sweep_clear(a, Point::new(93.0, 100.0), 5.0));
        assert!(!scene.sweep_clear(a, Point::new(94.5, 100.0), 5.0));
    }

    #[test]
    fn a_free_box_holds_no_obstacle_and_reaches_the_walls_it_meets() {
        use rand::{Rng, SeedableRng};
        let config = crate::ValidConfig::default();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for seed in 0..20 {
            let scene = crate::sim::maze_scene(&config, seed).with_obstacles(
                vec![],
                vec![
                    Shape::disc(Point::new(250.0, 250.0), 20.0),
                    Shape::polygon(&[
                        Point::new(600.0, 600.0),
                        Point::new(660.0, 610.0),
                        Point::new(620.0, 680.0),
                    ])
                    .unwrap(),
                ],
            );
            for _ in 0..200 {
                let p = Point::new(rng.random_range(0.0..1000.0), rng.random_range(0.0..1000.0));
                let dir = if rng.random() {
                    Vector::zeros()
                } else {
                    crate::geometry::unit(rng.random_range(0.0..360.0))
                };
                let free = scene.free_box_toward(p, rng.random(), dir);
                assert!(free.min.x <= p.x && p.x <= free.max.x, "{p:?} {free:?}");
                assert!(free.min.y <= p.y && p.y <= free.max.y, "{p:?} {free:?}");
                if free.extents().x > 0.0 && free.extents().y > 0.0 {
                    // Obstacles may touch its sides: its interior is clear.
                    let inside = free.inflated(-1e-9);
                    assert!(scene.box_clear(inside), "seed {seed}: {free:?} round {p:?}");
                    assert!(!scene.occupied(p));
                }
                // Shapes count by their bounding boxes: away from those, room at least as
                // wide as the clearance in some direction.
                let off_shapes = scene
                    .shapes()
                    .iter()
                    .all(|s| !s.aabb().inflated(3.0).contains(p));
                if off_shapes && scene.disc_clear(p, 3.0) {
                    assert!(free.extents().x.max(free.extents().y) >= 3.0, "{free:?}");
                }
            }
        }
    }
}
