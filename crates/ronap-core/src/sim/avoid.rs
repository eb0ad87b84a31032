//! One agent's step among other agents and the still scene, as the local planners and the
//! reactive pedestrians both take it: by ORCA (its nearest agents, the scene's obstacles within
//! the reach of its obstacle horizon, every agent grown by a safety margin, and the velocity ORCA
//! gives), or by the social force model (the pushes of the agents and of the still scene).

use crate::config::Forces;
use crate::geometry::social_force::{self, Walker};
use crate::geometry::{
    agent_neighbours_among, new_velocity, obstacle_neighbours, Agent, Horizon, Line, Obstacles,
    Point, Surroundings, Vector,
};
use crate::scene::Scene;

/// What one agent avoids with.
#[derive(Clone, Copy, Debug)]
pub struct Avoid<'a> {
    /// The agents, the one avoiding among them (radii as they are, without the margin).
    pub agents: &'a [Agent<f64>],
    /// The one avoiding: its index in `agents`.
    pub me: usize,
    /// The velocity it wants.
    pub preferred: Vector,
    /// Its horizons, speed limit and time step.
    pub horizon: Horizon<f64>,
    /// How far it looks for other agents (centre to centre).
    pub neighbour_dist: f64,
    /// Most agents it avoids at once (the nearest).
    pub max_neighbours: usize,
    /// Added to every agent's radius, its own too.
    pub margin: f64,
    /// The agents that may lie within `neighbour_dist` (indices into `agents`, each once, in
    /// any order), when a spatial grid has narrowed them down; `None`: every agent.
    pub candidates: Option<&'a [u32]>,
}

/// The scratch space of ORCA steps, kept between them.
#[derive(Clone, Debug, Default)]
pub struct Avoider {
    near: Vec<(f64, usize)>,
    others: Vec<Agent<f64>>,
    edges: Vec<(f64, usize)>,
    edge_list: Vec<usize>,
    lines: Vec<Line<f64>>,
    obstacles: Obstacles<f64>,
}

impl Avoider {
    /// The velocity ORCA gives `a.me` in `scene`.
    pub fn velocity(&mut self, scene: &Scene, a: &Avoid<'_>) -> Vector {
        match a.candidates {
            Some(c) => agent_neighbours_among(
                a.agents,
                a.me,
                c.iter().map(|&j| j as usize),
                a.neighbour_dist,
                a.max_neighbours,
                &mut self.near,
            ),
            None => agent_neighbours_among(
                a.agents,
                a.me,
                0..a.agents.len(),
                a.neighbour_dist,
                a.max_neighbours,
                &mut self.near,
            ),
        }
        self.others.clear();
        self.others.extend(self.near.iter().map(|&(_, j)| Agent {
            radius: a.agents[j].radius + a.margin,
            ..a.agents[j]
        }));
        let mut me = a.agents[a.me];
        me.radius += a.margin;
        let at = crate::geometry::Point::new(me.position.x, me.position.y);
        let reach = a.horizon.obstacles * a.horizon.max_speed + me.radius;
        scene.orca_obstacles_near(at, reach, &mut self.obstacles);
        obstacle_neighbours(
            &self.obstacles,
            me.position,
            me.radius,
            &a.horizon,
            &mut self.edges,
        );
        self.edge_list.clear();
        self.edge_list.extend(self.edges.iter().map(|&(_, e)| e));
        let around = Surroundings {
            agents: &self.others,
            obstacles: &self.obstacles,
            edges: &self.edge_list,
        };
        new_velocity(
            &me,
            a.preferred.into(),
            &around,
            &a.horizon,
            &mut self.lines,
        )
        .into()
    }
}

/// The velocity one step of the social force model gives the agent `me` wanting `preferred`, among `others`
/// (centres and radii) and the still scene, cut to `max_speed`.
pub fn social_force_velocity(
    forces: &Forces,
    me: &Agent<f64>,
    preferred: Vector,
    max_speed: f64,
    others: impl Iterator<Item = (Point, f64)>,
    scene: &Scene,
) -> Vector {
    let walker = Walker {
        position: Point::new(me.position.x, me.position.y),
        velocity: Vector::new(me.velocity.x, me.velocity.y),
        radius: me.radius,
    };
    let desired = social_force::desired_direction(preferred, walker.velocity);
    let mut push = Vector::zeros();
    // The others within reach are picked out with no branch on each (whether one is within
    // reach is a coin toss the processor mostly guesses wrong), a batch at a time, and their
    // pushes summed in their order: the same sum, to the bit, as over every one (a push from
    // beyond reach is zero, and adding zero changes no sum that starts at +0).
    let mut batch = [(Point::origin(), 0.0); 8];
    let mut kept = 0;
    let mut sum = |batch: &[(Point, f64)]| {
        for &(at, radius) in batch {
            push += social_force::agent_force(forces, &walker, desired, at, radius);
        }
    };
    for (at, radius) in others {
        batch[kept] = (at, radius);
        let d2 = (walker.position - at).norm_squared();
        kept += usize::from(social_force::maybe_in_reach(forces, d2));
        if kept == batch.len() {
            sum(&batch);
            kept = 0;
        }
    }
    sum(&batch[..kept]);
    // Beyond ten decay lengths a wall pushes by less than 1/20000 of its strength.
    let reach = walker.radius + 10.0 * forces.obstacle_range_px;
    scene.nearest_points(walker.position, reach, |q| {
        push += social_force::obstacle_force(forces, &walker, q);
    });
    social_force::next_velocity(forces, &walker, preferred, push, max_speed)
}
