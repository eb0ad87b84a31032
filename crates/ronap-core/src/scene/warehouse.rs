//! Generated logistics warehouses (docs/model.md "Warehouse scene").
//!
//! # Layout
//!
//! Bottom to top, inside outer walls of `wall_thickness_px` that line the scene border (so the
//! scene is closed and every aisle keeps its full width inside them):
//!
//! - the loading area, `loading_px` deep across the whole width, with nothing in it;
//! - a border aisle of `aisle_px`;
//! - `rack_pairs` pairs of rack rows, each pair two racks of `rack_depth_px` back to back (one box
//!   per rack, so a rack position holds two touching boxes), the pairs separated by aisles of
//!   `aisle_px`;
//! - an aisle of `aisle_px` above the last pair, under the top wall.
//!
//! Left to right: a side aisle of `aisle_px`, `racks_per_row` racks of `rack_length_px` with a
//! cross aisle of `aisle_px` after every `cross_aisle_every` racks (none after the last; `0`
//! means no cross aisles), and a side aisle of `aisle_px`. The size follows:
//!
//! ```text
//! width  = 2 wall + 2 aisle + racks_per_row * rack_length + cross_aisles * aisle
//! height = 2 wall + loading + aisle + rack_pairs * (2 rack_depth + aisle)
//! ```
//!
//! with `cross_aisles = (racks_per_row - 1) / cross_aisle_every` (integer division). The default
//! warehouse is 764 x 544 px.
//!
//! # Clutter
//!
//! Pallets stand on *spots*: the stretch of the aisle above each pair (the aisles between pairs and
//! the top aisle) beside one rack, one rack length long; and the stretch of each side aisle beside
//! one rack pair, two rack depths long. The loading area, the border aisle in front of it, the
//! cross aisles and every crossing of two aisles stay clear. Each spot, in a fixed order, draws
//! from the scene stream whether it holds a pallet (probability `clutter`), against which of its
//! aisle's two faces, and where along the spot; the pallet, a `pallet_px` square, stands flush
//! against that face inside the spot. Every spot makes the same draws whatever happens to its
//! pallet, so the same config and stream give the same warehouse.
//!
//! The robot needs a lane of [`lane_px`]: its diameter plus a margin of its radius (at least one
//! 5 px free-space cell) on each side. A pallet is kept only if
//!
//! 1. it leaves that lane open across its aisle (`aisle_px - pallet_px >= lane`; otherwise the
//!    config's pallets are too large for this robot and the warehouse has none), and
//! 2. it is at least a lane away from every pallet already kept against the *other* face of the
//!    same aisle.
//!
//! Why this keeps the free space one region: group each obstacle with what it stands against, a
//! block of racks (the racks of one pair between two cross aisles) with the pallets flush against
//! it, and the walls with the pallets flush against them. Without pallets any two groups are at
//! least an aisle apart. A pallet reaches `pallet_px` into one aisle only, never into a crossing
//! or a cross aisle, so it comes near only the other face of its own aisle (rule 1) and the
//! pallets against that face (rule 2). Pallets of two different aisles come close only around a
//! corner of one rack block, flush against two of its sides: both belong to that block's group,
//! and what lies between them is a notch in the group, not a passage. So every two groups stay at
//! least a lane apart, the walls' group encloses all the others, and a disc passes between any two
//! of them: the space left for its centre is the inside of the walls minus disjoint solid blobs,
//! which is connected, and at least a grid cell wide everywhere. Pallets against the same face
//! may leave gaps between them too narrow for the robot, but such a gap opens onto the lane and
//! is a dead end, not a wall.
//!
//! A robot too wide for the bare aisles (`aisle_px < 2 * radius`) cannot be helped by the
//! generator; it gets no pallets and the racks as configured.

use crate::config::WarehouseConfig;
use crate::geometry::{Aabb, Point};

/// Smallest margin a pallet leaves beside the robot on each side, px: one cell of the free-space
/// grid the project samples, so the open lane always holds a row of free cells even for a small
/// robot.
const MIN_MARGIN_PX: f64 = 5.0;

/// Width of the lane a pallet must leave open for a robot of `radius_px`: its diameter plus a
/// margin of `max(radius_px, 5 px)` on each side (20 px for the default radius of 5).
pub fn lane_px(radius_px: f64) -> f64 {
    2.0 * radius_px + 2.0 * radius_px.max(MIN_MARGIN_PX)
}

/// A generated warehouse: its size and its obstacles as axis-aligned boxes.
#[derive(Clone, Debug, PartialEq)]
pub struct Warehouse {
    /// Scene width, px.
    pub width_px: f64,
    /// Scene height, px.
    pub height_px: f64,
    /// The racks.
    pub racks: Vec<Aabb>,
    /// The pallets of clutter.
    pub pallets: Vec<Aabb>,
    /// The outer walls.
    pub walls: Vec<Aabb>,
}

impl Warehouse {
    /// The warehouse `config` describes, its clutter drawn from `rng`, kept connected for a robot
    /// of `robot_radius_px` (see the module documentation for the layout and the clutter rules).
    pub fn generate(
        config: &WarehouseConfig,
        robot_radius_px: f64,
        rng: &mut impl rand::Rng,
    ) -> Self {
        let layout = Layout::new(config);
        let pallets = layout.pallets(config, robot_radius_px, rng);
        Self {
            width_px: layout.width,
            height_px: layout.height,
            racks: layout.racks(),
            pallets,
            walls: layout.walls(),
        }
    }

    /// Every obstacle box: walls, racks, pallets.
    pub fn boxes(&self) -> Vec<Aabb> {
        let mut all = self.walls.clone();
        all.extend_from_slice(&self.racks);
        all.extend_from_slice(&self.pallets);
        all
    }
}

/// Where everything of a warehouse goes, px.
struct Layout {
    /// Wall thickness.
    wall: f64,
    /// Aisle width.
    aisle: f64,
    /// Rack length along its row.
    rack_length: f64,
    /// Depth of one rack.
    rack_depth: f64,
    /// Scene width.
    width: f64,
    /// Scene height.
    height: f64,
    /// Left edge of each rack position along a row, left to right.
    rack_x: Vec<f64>,
    /// Bottom edge of each rack pair, bottom to top.
    pair_y: Vec<f64>,
}

impl Layout {
    fn new(config: &WarehouseConfig) -> Self {
        let wall = config.wall_thickness_px;
        let aisle = config.aisle_px;
        let rack_length = config.rack_length_px;
        let rack_depth = config.rack_depth_px;
        let every = config.cross_aisle_every as usize;
        // Cross aisles left of position `i`; none at all when `every` is 0.
        let cross_before = |i: usize| i.checked_div(every).unwrap_or(0);
        let n = config.racks_per_row as usize;
        let rack_x: Vec<f64> = (0..n)
            .map(|i| wall + aisle + i as f64 * rack_length + cross_before(i) as f64 * aisle)
            .collect();
        let (width, height) = config.size_px();
        let pair_pitch = 2.0 * rack_depth + aisle;
        let first_pair = wall + config.loading_px + aisle;
        let pairs = config.rack_pairs as usize;
        let pair_y: Vec<f64> = (0..pairs)
            .map(|k| first_pair + k as f64 * pair_pitch)
            .collect();
        Self {
            wall,
            aisle,
            rack_length,
            rack_depth,
            width,
            height,
            rack_x,
            pair_y,
        }
    }

    /// Four walls lining the border inside `[0, width] x [0, height]`: bottom and top across the
    /// whole width, left and right between them.
    fn walls(&self) -> Vec<Aabb> {
        let (w, h, t) = (self.width, self.height, self.wall);
        vec![
            Aabb::from_corners(Point::new(0.0, 0.0), Point::new(w, t)),
            Aabb::from_corners(Point::new(0.0, h - t), Point::new(w, h)),
            Aabb::from_corners(Point::new(0.0, t), Point::new(t, h - t)),
            Aabb::from_corners(Point::new(w - t, t), Point::new(w, h - t)),
        ]
    }

    /// One box per rack: per pair bottom to top, per position left to right, the lower rack then
    /// the upper one.
    fn racks(&self) -> Vec<Aabb> {
        let d = self.rack_depth;
        let mut racks = Vec::with_capacity(2 * self.pair_y.len() * self.rack_x.len());
        for &y in &self.pair_y {
            for &x in &self.rack_x {
                let x1 = x + self.rack_length;
                racks.push(Aabb::from_corners(Point::new(x, y), Point::new(x1, y + d)));
                racks.push(Aabb::from_corners(
                    Point::new(x, y + d),
                    Point::new(x1, y + 2.0 * d),
                ));
            }
        }
        racks
    }

    /// The spots that may hold a pallet, in drawing order: the aisle above each pair (bottom to
    /// top, one spot per rack position), then the left and the right side aisle (one spot beside
    /// each pair).
    fn spots(&self) -> Vec<Spot> {
        let mut spots = Vec::new();
        for (k, &y) in self.pair_y.iter().enumerate() {
            let floor = y + 2.0 * self.rack_depth;
            for &x in &self.rack_x {
                spots.push(Spot {
                    aisle: k,
                    along_x: true,
                    faces: (floor, floor + self.aisle),
                    stretch: (x, x + self.rack_length),
                });
            }
        }
        let sides = [
            (self.wall, self.wall + self.aisle),
            (self.width - self.wall - self.aisle, self.width - self.wall),
        ];
        for (s, faces) in sides.into_iter().enumerate() {
            for &y in &self.pair_y {
                spots.push(Spot {
                    aisle: self.pair_y.len() + s,
                    along_x: false,
                    faces,
                    stretch: (y, y + 2.0 * self.rack_depth),
                });
            }
        }
        spots
    }

    /// The pallets, drawn spot by spot and kept by the rules of the module documentation.
    fn pallets(
        &self,
        config: &WarehouseConfig,
        robot_radius_px: f64,
        rng: &mut impl rand::Rng,
    ) -> Vec<Aabb> {
        let size = config.pallet_px;
        let lane = lane_px(robot_radius_px);
        // Rule 1, the same for every aisle since they are all `aisle_px` wide.
        let leaves_lane = size > 0.0 && self.aisle - size >= lane;
        let mut kept: Vec<(usize, bool, Aabb)> = Vec::new();
        for spot in self.spots() {
            // Always three draws, so each spot's pallet depends only on the stream position.
            let present = rng.random::<f64>() < config.clutter;
            let high_face = rng.random::<bool>();
            let jitter = rng.random::<f64>();
            let room = spot.stretch.1 - spot.stretch.0 - size;
            if !present || !leaves_lane || room < 0.0 {
                continue;
            }
            let pallet = spot.pallet(size, high_face, jitter * room);
            // Rule 2: a lane from every pallet against the other face of this aisle.
            let clear = kept
                .iter()
                .filter(|(aisle, high, _)| *aisle == spot.aisle && *high != high_face)
                .all(|(_, _, other)| box_distance(&pallet, other) >= lane);
            if clear {
                kept.push((spot.aisle, high_face, pallet));
            }
        }
        kept.into_iter().map(|(_, _, pallet)| pallet).collect()
    }
}

/// A stretch of aisle that may hold one pallet.
struct Spot {
    /// Which aisle the spot is in (pallets of one aisle are checked against each other).
    aisle: usize,
    /// Whether the aisle runs along x (its faces are then horizontal lines).
    along_x: bool,
    /// The aisle's two faces, low then high, as coordinates across the aisle.
    faces: (f64, f64),
    /// Where the spot starts and ends along the aisle.
    stretch: (f64, f64),
}

impl Spot {
    /// A pallet of side `size` flush against the high or low face, `offset` from the spot's start.
    fn pallet(&self, size: f64, high_face: bool, offset: f64) -> Aabb {
        let along = self.stretch.0 + offset;
        let across = if high_face {
            self.faces.1 - size
        } else {
            self.faces.0
        };
        let (x, y) = if self.along_x {
            (along, across)
        } else {
            (across, along)
        };
        Aabb::from_corners(Point::new(x, y), Point::new(x + size, y + size))
    }
}

/// Euclidean distance between two boxes (0 when they touch or overlap).
fn box_distance(a: &Aabb, b: &Aabb) -> f64 {
    let dx = (a.min.x - b.max.x).max(b.min.x - a.max.x).max(0.0);
    let dy = (a.min.y - b.max.y).max(b.min.y - a.max.y).max(0.0);
    dx.hypot(dy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::freespace::FreeGrid;
    use crate::scene::Scene;
    use crate::sim::{stream, Stream};
    use proptest::prelude::*;

    /// The free loading area along the bottom, inside the walls.
    fn loading_area(config: &WarehouseConfig) -> Aabb {
        let layout = Layout::new(config);
        let t = layout.wall;
        Aabb::from_corners(
            Point::new(t, t),
            Point::new(layout.width - t, t + config.loading_px),
        )
    }

    fn generate(config: &WarehouseConfig, radius: f64, seed: u64) -> Warehouse {
        Warehouse::generate(config, radius, &mut stream(seed, Stream::Scene))
    }

    fn scene(warehouse: &Warehouse) -> Scene {
        Scene::from_boxes(
            warehouse.width_px,
            warehouse.height_px,
            warehouse.boxes(),
            50.0,
        )
    }

    /// Free regions of the warehouse for a robot of `radius`, as the project samples them.
    fn regions(warehouse: &Warehouse, radius: f64) -> usize {
        FreeGrid::new(&scene(warehouse), radius, 5.0, radius).region_count()
    }

    /// Generates over 300 seeds, checks each is one region, and returns the pallets placed.
    fn assert_connected(config: &WarehouseConfig, radius: f64) -> usize {
        let mut pallets = 0;
        for seed in 0..300 {
            let warehouse = generate(config, radius, seed);
            let count = regions(&warehouse, radius);
            assert_eq!(count, 1, "seed {seed}, radius {radius}: {count} regions");
            pallets += warehouse.pallets.len();
        }
        pallets
    }

    fn overlaps(a: &Aabb, b: &Aabb) -> bool {
        a.min.x < b.max.x && b.min.x < a.max.x && a.min.y < b.max.y && b.min.y < a.max.y
    }

    #[test]
    fn default_warehouse_is_one_region() {
        let pallets = assert_connected(&WarehouseConfig::default(), 5.0);
        assert!(pallets > 0, "the default clutter places pallets");
    }

    #[test]
    fn full_clutter_is_one_region() {
        let config = WarehouseConfig {
            clutter: 1.0,
            ..WarehouseConfig::default()
        };
        let pallets = assert_connected(&config, 5.0);
        // 5 aisles of 12 spots and 2 side aisles of 5: rule 2 drops some, not most.
        assert!(pallets > 300 * 40, "{pallets} pallets");
    }

    #[test]
    fn deep_pallets_are_one_region() {
        // 20 px pallets leave exactly the 20 px lane; two against opposite faces would close the
        // aisle, so rule 2 must keep them apart.
        let config = WarehouseConfig {
            clutter: 1.0,
            pallet_px: 20.0,
            ..WarehouseConfig::default()
        };
        assert!(assert_connected(&config, 5.0) > 0);
    }

    #[test]
    fn bigger_robot_is_one_region() {
        // The default pallets leave 28 px, less than the 32 px lane of radius 8: none are placed.
        let pallets = assert_connected(&WarehouseConfig::default(), 8.0);
        assert_eq!(pallets, 0);
        // Smaller pallets leave exactly the lane and are placed.
        let config = WarehouseConfig {
            clutter: 1.0,
            pallet_px: 8.0,
            ..WarehouseConfig::default()
        };
        assert!(assert_connected(&config, 8.0) > 0);
    }

    #[test]
    fn other_configs_are_one_region() {
        let configs = [
            WarehouseConfig {
                rack_pairs: 1,
                racks_per_row: 1,
                clutter: 1.0,
                ..WarehouseConfig::default()
            },
            WarehouseConfig {
                rack_pairs: 3,
                racks_per_row: 7,
                cross_aisle_every: 0,
                aisle_px: 24.0,
                pallet_px: 4.0,
                clutter: 1.0,
                loading_px: 30.0,
                ..WarehouseConfig::default()
            },
            WarehouseConfig {
                racks_per_row: 5,
                cross_aisle_every: 1,
                rack_length_px: 10.0,
                rack_depth_px: 3.0,
                pallet_px: 9.0,
                clutter: 0.7,
                ..WarehouseConfig::default()
            },
        ];
        for config in &configs {
            for radius in [2.0, 5.0, 7.0] {
                for seed in 0..40 {
                    let warehouse = generate(config, radius, seed);
                    assert_eq!(regions(&warehouse, radius), 1, "{config:?} r {radius}");
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Any layout whose bare aisles hold the robot's lane stays one region with clutter.
        #[test]
        fn random_configs_are_one_region(
            seed in any::<u64>(),
            rack_pairs in 1u32..4,
            racks_per_row in 1u32..9,
            cross_aisle_every in 0u32..4,
            rack_length_px in 5.0f64..60.0,
            rack_depth_px in 2.0f64..20.0,
            radius in 1.0f64..9.0,
            extra_aisle in 0.0f64..30.0,
            pallet_px in 1.0f64..40.0,
            clutter in 0.0f64..=1.0,
        ) {
            let config = WarehouseConfig {
                rack_pairs,
                racks_per_row,
                cross_aisle_every,
                rack_length_px,
                rack_depth_px,
                aisle_px: lane_px(radius) + extra_aisle,
                loading_px: 20.0,
                clutter,
                pallet_px,
                ..WarehouseConfig::default()
            };
            let warehouse = generate(&config, radius, seed);
            prop_assert_eq!(regions(&warehouse, radius), 1);
        }

        /// No valid config panics, however small or large its lengths.
        #[test]
        fn valid_configs_do_not_panic(
            seed in any::<u64>(),
            rack_pairs in 1u32..6,
            racks_per_row in 1u32..6,
            cross_aisle_every in 0u32..8,
            lengths in proptest::array::uniform6(0.01f64..500.0),
            clutter in 0.0f64..=1.0,
            radius in 0.01f64..50.0,
        ) {
            let [rack_length_px, rack_depth_px, aisle_px, loading_px, pallet_px, wall_thickness_px] =
                lengths;
            let config = WarehouseConfig {
                rack_pairs,
                racks_per_row,
                rack_length_px,
                rack_depth_px,
                aisle_px,
                cross_aisle_every,
                loading_px,
                clutter,
                pallet_px,
                wall_thickness_px,
            };
            let warehouse = generate(&config, radius, seed);
            prop_assert_eq!(warehouse.racks.len(), 2 * (rack_pairs * racks_per_row) as usize);
            prop_assert_eq!(config.size_px(), (warehouse.width_px, warehouse.height_px));
        }
    }

    #[test]
    fn sizes_and_counts_follow_the_config() {
        let config = WarehouseConfig::default();
        let warehouse = generate(&config, 5.0, 1);
        assert_eq!((warehouse.width_px, warehouse.height_px), (764.0, 544.0));
        assert_eq!(config.size_px(), (764.0, 544.0));
        assert_eq!(warehouse.racks.len(), 2 * 5 * 12);
        assert_eq!(warehouse.walls.len(), 4);
        for rack in &warehouse.racks {
            let e = rack.extents();
            assert_eq!((e.x, e.y), (50.0, 15.0));
        }
        // Gaps between neighbouring racks of the bottom row: the two cross aisles.
        let mut row: Vec<f64> = warehouse
            .racks
            .iter()
            .filter(|r| r.min.y == 2.0 + 150.0 + 40.0)
            .map(|r| r.min.x)
            .collect();
        row.sort_by(f64::total_cmp);
        assert_eq!(row.len(), 12);
        assert_eq!(row[0], 2.0 + 40.0);
        let gaps: Vec<f64> = row.windows(2).map(|w| w[1] - w[0] - 50.0).collect();
        assert_eq!(gaps.iter().filter(|&&g| g == 40.0).count(), 2);
        assert_eq!(gaps.iter().filter(|&&g| g == 0.0).count(), 9);
        // The last rack ends one side aisle and a wall short of the right edge.
        assert_eq!(row[11] + 50.0, 764.0 - 2.0 - 40.0);
        // The top pair ends one aisle and a wall below the top.
        let top = warehouse.racks.iter().map(|r| r.max.y).fold(0.0, f64::max);
        assert_eq!(top, 544.0 - 2.0 - 40.0);

        let loading = loading_area(&config);
        assert_eq!(loading.extents().y, 150.0);
        for b in warehouse.boxes() {
            assert!(!overlaps(&b, &loading), "{b:?} in the loading area");
        }

        let plain = WarehouseConfig {
            cross_aisle_every: 0,
            rack_pairs: 2,
            racks_per_row: 3,
            ..WarehouseConfig::default()
        };
        let (w, h) = plain.size_px();
        assert_eq!(w, 2.0 * 2.0 + 2.0 * 40.0 + 3.0 * 50.0);
        assert_eq!(h, 2.0 * 2.0 + 150.0 + 40.0 + 2.0 * (30.0 + 40.0));
        assert_eq!(generate(&plain, 5.0, 0).racks.len(), 2 * 2 * 3);
    }

    #[test]
    fn pallets_stand_in_aisles() {
        let config = WarehouseConfig {
            clutter: 1.0,
            ..WarehouseConfig::default()
        };
        let loading_front = 2.0 + 150.0 + 40.0;
        for seed in 0..50 {
            let warehouse = generate(&config, 5.0, seed);
            for pallet in &warehouse.pallets {
                let e = pallet.extents();
                assert!(
                    (e.x - 12.0).abs() < 1e-9 && (e.y - 12.0).abs() < 1e-9,
                    "{e:?}"
                );
                assert!(pallet.min.y >= loading_front, "{pallet:?} before the racks");
                for other in warehouse.walls.iter().chain(&warehouse.racks) {
                    assert!(!overlaps(pallet, other), "{pallet:?} overlaps {other:?}");
                }
                // Flush against a face: touching a rack or a wall.
                let touches = warehouse
                    .walls
                    .iter()
                    .chain(&warehouse.racks)
                    .any(|b| box_distance(pallet, b) < 1e-9);
                assert!(touches, "{pallet:?} stands free");
            }
        }
    }

    #[test]
    fn too_large_pallets_are_skipped() {
        let config = WarehouseConfig {
            clutter: 1.0,
            pallet_px: 30.0,
            ..WarehouseConfig::default()
        };
        let warehouse = generate(&config, 5.0, 7);
        assert!(warehouse.pallets.is_empty());
        assert_eq!(regions(&warehouse, 5.0), 1);
        let none = WarehouseConfig {
            clutter: 0.0,
            ..WarehouseConfig::default()
        };
        assert!(generate(&none, 5.0, 7).pallets.is_empty());
    }

    #[test]
    fn same_seed_same_warehouse() {
        let config = WarehouseConfig::default();
        assert_eq!(generate(&config, 5.0, 42), generate(&config, 5.0, 42));
        let different = (0..10)
            .filter(|&s| generate(&config, 5.0, s).pallets != generate(&config, 5.0, s + 1).pallets)
            .count();
        assert_eq!(different, 10);
        // The layout does not depend on the stream.
        let (a, b) = (generate(&config, 5.0, 1), generate(&config, 5.0, 2));
        assert_eq!((a.racks, a.walls), (b.racks, b.walls));
    }

    #[test]
    fn boxes_lie_inside_the_scene() {
        let configs = [
            WarehouseConfig::default(),
            WarehouseConfig {
                clutter: 1.0,
                ..WarehouseConfig::default()
            },
            WarehouseConfig {
                rack_pairs: 1,
                racks_per_row: 1,
                cross_aisle_every: 0,
                clutter: 1.0,
                pallet_px: 1.0,
                ..WarehouseConfig::default()
            },
        ];
        for config in &configs {
            for seed in 0..20 {
                let warehouse = generate(config, 5.0, seed);
                let bounds = Aabb::from_corners(
                    Point::origin(),
                    Point::new(warehouse.width_px, warehouse.height_px),
                );
                for b in warehouse.boxes() {
                    assert!(bounds.contains(b.min) && bounds.contains(b.max), "{b:?}");
                }
            }
        }
    }
}
