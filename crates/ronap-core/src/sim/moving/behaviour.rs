//! The seam for a moving obstacle's motion: a [`Behaviour`] chooses where its obstacle goes each
//! step, seeing the other obstacles and the robots through [`Neighbours`].

use crate::geometry::Point;
use crate::scene::Scene;
use crate::sim::moving::heading::State;
use crate::sim::moving::{Body, Disc, Entry};
use crate::sim::rng::Rng;
use std::fmt::Debug;

/// The obstacle a [`Behaviour`] moves, as it stands at the start of its move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Agent {
    /// Its index among the episode's moving obstacles.
    pub index: usize,
    /// Its centre, px.
    pub position: Point,
    /// Its body.
    pub body: Body,
    /// Its speed, px per step (`speed_px`).
    pub speed_px: f64,
}

/// What an obstacle's behaviour sees of the others: the obstacles near a point (as they stand,
/// those already moved this step where they went), and the robots.
pub struct Neighbours<'a> {
    pub(super) state: &'a State,
    pub(super) entries: &'a [Entry],
    pub(super) robots: &'a [Disc],
}

impl Neighbours<'_> {
    /// Calls `f` with the index, centre and body of every present obstacle whose centre lies
    /// within `distance_px` of `p`, in no particular order (the asking obstacle too: compare
    /// the index with its [`Agent::index`]).
    pub fn obstacles_within(
        &self,
        p: Point,
        distance_px: f64,
        mut f: impl FnMut(usize, Point, Body),
    ) {
        let d2 = distance_px * distance_px;
        // During a step the obstacles moved before this one may be a step further from where
        // the order last saw them than its age allows for: one more step's drift covers them.
        self.state.near(p, distance_px + self.state.drift, |i| {
            let at = self.state.position(i);
            if self.entries[i].present() && (at - p).norm_squared() <= d2 {
                f(i, at, self.entries[i].body);
            }
        });
    }

    /// The robots, as discs where they stand before their move.
    pub fn robots(&self) -> &[Disc] {
        self.robots
    }
}

/// How a moving obstacle chooses its step (one file per behaviour; the heading motions are
/// moved together instead). The engine then refuses a move that would touch a robot: the
/// obstacle stays and the robot is charged a dynamic collision.
pub trait Behaviour: Send + Sync + Debug {
    /// Where the obstacle `me` goes this step: a point at most `me.speed_px` from
    /// `me.position` (one further is brought back to that distance along the same line), or
    /// `None` to stay without a contact check. `rng` is the episode's
    /// moving-obstacle stream, drawn from in obstacle order.
    fn next(
        &mut self,
        me: &Agent,
        near: &Neighbours<'_>,
        scene: &Scene,
        rng: &mut Rng,
    ) -> Option<Point>;

    /// A copy of this behaviour in its current state (an episode is cloned with its obstacles).
    fn boxed_clone(&self) -> Box<dyn Behaviour>;
}

impl Clone for Box<dyn Behaviour> {
    fn clone(&self) -> Self {
        self.boxed_clone()
    }
}
