//! DQN's replay memory: a ring of transitions, sampled uniformly or in proportion to priorities
//! (a sum tree), and the n-step returns that fill it.

use crate::LearnError;
use candle_core::{Device, Tensor};
use rand::Rng as _;
use rand_chacha::ChaCha8Rng;
use ronap_core::Status;
use std::collections::VecDeque;

/// One (possibly n-step) transition: the return `reward` of up to n steps from `observation`
/// and the factor `bootstrap` on `max Q(next_observation)` in its target (`gamma^m` after `m`
/// steps, 0 where the episode terminated).
#[derive(Clone, Debug, PartialEq)]
pub struct Transition {
    /// Where it started.
    pub observation: Vec<f32>,
    /// The first action.
    pub action: u32,
    /// The discounted rewards of its steps, summed.
    pub reward: f32,
    /// Where it ended.
    pub next_observation: Vec<f32>,
    /// The discount on the value of `next_observation` (0: terminal).
    pub bootstrap: f32,
}

/// A mini-batch as tensors, with the memory slots it came from and the loss weight of each.
pub struct Sample {
    /// Observations (`n x width`).
    pub observations: Tensor,
    /// Actions (`n x 1`, u32).
    pub actions: Tensor,
    /// Returns (`n`).
    pub rewards: Tensor,
    /// Next observations (`n x width`).
    pub next_observations: Tensor,
    /// Bootstrap factors (`n`).
    pub bootstrap: Tensor,
    /// Importance weights (`n`; all 1 without priorities).
    pub weights: Tensor,
    /// The slots drawn, for [`Replay::update_priorities`].
    pub slots: Vec<usize>,
}

/// The replay memory: a ring of transitions; the oldest go first.
pub struct Replay {
    width: usize,
    capacity: usize,
    observations: Vec<f32>,
    next_observations: Vec<f32>,
    actions: Vec<u32>,
    rewards: Vec<f32>,
    bootstrap: Vec<f32>,
    next: usize,
    priorities: Option<SumTree>,
    /// The largest priority so far (new transitions get it).
    max_priority: f64,
    alpha: f64,
}

impl Replay {
    /// An empty memory of `capacity` transitions of observations `width` wide; with `alpha`,
    /// prioritised.
    pub fn new(width: usize, capacity: usize, alpha: Option<f64>) -> Self {
        Self {
            width,
            capacity,
            observations: Vec::new(),
            next_observations: Vec::new(),
            actions: Vec::new(),
            rewards: Vec::new(),
            bootstrap: Vec::new(),
            next: 0,
            priorities: alpha.map(|_| SumTree::new(capacity)),
            max_priority: 1.0,
            alpha: alpha.unwrap_or(0.0),
        }
    }

    /// Transitions held.
    pub fn len(&self) -> usize {
        self.actions.len()
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.actions.is_empty()
    }

    /// Adds `t`, over the oldest once full.
    pub fn push(&mut self, t: &Transition) {
        let w = self.width;
        let i = self.next;
        if self.len() < self.capacity {
            self.observations.extend_from_slice(&t.observation);
            self.next_observations
                .extend_from_slice(&t.next_observation);
            self.actions.push(t.action);
            self.rewards.push(t.reward);
            self.bootstrap.push(t.bootstrap);
        } else {
            self.observations[i * w..(i + 1) * w].copy_from_slice(&t.observation);
            self.next_observations[i * w..(i + 1) * w].copy_from_slice(&t.next_observation);
            self.actions[i] = t.action;
            self.rewards[i] = t.reward;
            self.bootstrap[i] = t.bootstrap;
        }
        if let Some(tree) = &mut self.priorities {
            tree.set(i, self.max_priority.powf(self.alpha));
        }
        self.next = (self.next + 1) % self.capacity;
    }

    /// A mini-batch of `n`: uniform, or proportional to priority (one draw in each of `n` equal
    /// slices of the total) with importance weights at exponent `beta`.
    pub fn sample(&self, n: usize, beta: f64, rng: &mut ChaCha8Rng) -> Result<Sample, LearnError> {
        let len = self.len();
        let slots: Vec<usize> = match &self.priorities {
            None => (0..n).map(|_| rng.random_range(0..len)).collect(),
            Some(tree) => {
                let slice = tree.total() / n as f64;
                (0..n)
                    .map(|k| {
                        tree.find((k as f64 + rng.random::<f64>()) * slice)
                            .min(len - 1)
                    })
                    .collect()
            }
        };
        let weights: Vec<f32> = match &self.priorities {
            None => vec![1.0; n],
            Some(tree) => {
                let total = tree.total();
                let w: Vec<f64> = slots
                    .iter()
                    .map(|&i| (len as f64 * tree.get(i) / total).powf(-beta))
                    .collect();
                let max = w.iter().copied().fold(f64::MIN_POSITIVE, f64::max);
                w.iter().map(|v| (v / max) as f32).collect()
            }
        };
        let w = self.width;
        let mut o = Vec::with_capacity(n * w);
        let mut o2 = Vec::with_capacity(n * w);
        let (mut a, mut r, mut b) = (Vec::new(), Vec::new(), Vec::new());
        for &i in &slots {
            o.extend_from_slice(&self.observations[i * w..(i + 1) * w]);
            o2.extend_from_slice(&self.next_observations[i * w..(i + 1) * w]);
            a.push(self.actions[i]);
            r.push(self.rewards[i]);
            b.push(self.bootstrap[i]);
        }
        let cpu = &Device::Cpu;
        Ok(Sample {
            observations: crate::net::batch(o, w)?,
            actions: Tensor::from_vec(a, (n, 1), cpu)?,
            rewards: Tensor::from_vec(r, n, cpu)?,
            next_observations: crate::net::batch(o2, w)?,
            bootstrap: Tensor::from_vec(b, n, cpu)?,
            weights: Tensor::from_vec(weights, n, cpu)?,
            slots,
        })
    }

    /// Sets the priorities of the `slots` drawn to their TD errors' sizes (no-op when uniform).
    pub fn update_priorities(&mut self, slots: &[usize], errors: &[f32]) {
        let Some(tree) = &mut self.priorities else {
            return;
        };
        for (&i, &e) in slots.iter().zip(errors) {
            let p = f64::from(e.abs()) + 1e-3;
            let p = if p.is_finite() { p } else { self.max_priority };
            self.max_priority = self.max_priority.max(p);
            tree.set(i, p.powf(self.alpha));
        }
    }
}

/// A binary tree of sums over `capacity` leaves: set a leaf and find the leaf where a running
/// sum passes a mass, both in O(log n).
struct SumTree {
    leaves: usize,
    nodes: Vec<f64>,
}

impl SumTree {
    fn new(capacity: usize) -> Self {
        let leaves = capacity.max(1).next_power_of_two();
        Self {
            leaves,
            nodes: vec![0.0; 2 * leaves],
        }
    }

    fn total(&self) -> f64 {
        self.nodes[1]
    }

    fn get(&self, i: usize) -> f64 {
        self.nodes[self.leaves + i]
    }

    fn set(&mut self, i: usize, value: f64) {
        let mut k = self.leaves + i;
        self.nodes[k] = value;
        while k > 1 {
            k /= 2;
            self.nodes[k] = self.nodes[2 * k] + self.nodes[2 * k + 1];
        }
    }

    /// The leaf where the running sum from the left first exceeds `mass`.
    fn find(&self, mass: f64) -> usize {
        let mut mass = mass.clamp(0.0, self.total());
        let mut k = 1;
        while k < self.leaves {
            let left = self.nodes[2 * k];
            if mass < left || self.nodes[2 * k + 1] <= 0.0 {
                k *= 2;
            } else {
                mass -= left;
                k = 2 * k + 1;
            }
        }
        k - self.leaves
    }
}

/// The last steps of one environment's episode, turned into n-step transitions of `n` steps
/// discounted by `gamma`.
#[derive(Debug)]
pub struct NStep {
    steps: VecDeque<(Vec<f32>, u32, f32)>,
    n: usize,
    gamma: f64,
}

impl NStep {
    /// Transitions of `n` steps (at least 1), rewards discounted by `gamma`.
    pub fn new(n: usize, gamma: f64) -> Self {
        Self {
            steps: VecDeque::new(),
            n,
            gamma,
        }
    }

    /// Adds the step from `observation` by `action` with `reward`, to `next`, after which the
    /// episode stands at `status`; returns the transitions that are complete: the one starting
    /// `n` steps back, or, when the episode ended, every one still pending (bootstrapped unless
    /// the task itself ended it: [`Status::is_terminated`]).
    pub fn add(
        &mut self,
        observation: &[f32],
        action: u32,
        reward: f32,
        next: &[f32],
        status: Status,
    ) -> Vec<Transition> {
        let (done, terminated) = (status.is_done(), status.is_terminated());
        let (n, gamma) = (self.n, self.gamma);
        self.steps.push_back((observation.to_vec(), action, reward));
        let mut out = Vec::new();
        let make = |steps: &VecDeque<(Vec<f32>, u32, f32)>, terminal: bool| {
            let (o, a, _) = &steps[0];
            let mut ret = 0.0f64;
            let mut discount = 1.0f64;
            for (_, _, r) in steps {
                ret += discount * f64::from(*r);
                discount *= gamma;
            }
            Transition {
                observation: o.clone(),
                action: *a,
                reward: ret as f32,
                next_observation: next.to_vec(),
                bootstrap: if terminal { 0.0 } else { discount as f32 },
            }
        };
        if done {
            while !self.steps.is_empty() {
                out.push(make(&self.steps, terminated));
                self.steps.pop_front();
            }
        } else if self.steps.len() >= n.max(1) {
            out.push(make(&self.steps, false));
            self.steps.pop_front();
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn obs(v: f32) -> Vec<f32> {
        vec![v, v]
    }

    #[test]
    fn n_step_returns_by_hand() {
        // Rewards 1, 2, 4, 8 then success: with n = 3, gamma 0.5.
        let g = 0.5;
        let mut n = NStep::new(3, g);
        let mut got = Vec::new();
        for (k, r) in [1.0f32, 2.0, 4.0].iter().enumerate() {
            got.extend(n.add(
                &obs(k as f32),
                k as u32,
                *r,
                &obs(k as f32 + 1.0),
                Status::Running,
            ));
        }
        // Three steps in: the first transition, 1 + 0.5*2 + 0.25*4 = 3, bootstrapped by 0.125
        // from the third step's end.
        assert_eq!(got.len(), 1);
        assert_eq!(got[0].observation, obs(0.0));
        assert_eq!(got[0].action, 0);
        assert_eq!(got[0].reward, 3.0);
        assert_eq!(got[0].next_observation, obs(3.0));
        assert_eq!(got[0].bootstrap, 0.125);
        // The episode ends at the goal on the fourth step: the two pending and the last one,
        // none bootstrapped.
        let end = n.add(&obs(3.0), 1, 8.0, &obs(4.0), Status::Success);
        let rewards: Vec<f32> = end.iter().map(|t| t.reward).collect();
        assert_eq!(
            rewards,
            vec![2.0 + 0.5 * 4.0 + 0.25 * 8.0, 4.0 + 0.5 * 8.0, 8.0]
        );
        assert!(end
            .iter()
            .all(|t| t.bootstrap == 0.0 && t.next_observation == obs(4.0)));
        // A time-out ends the episode without ending the task: the pending ones bootstrap.
        let mut n = NStep::new(3, g);
        n.add(&obs(0.0), 0, 1.0, &obs(1.0), Status::Running);
        let end = n.add(&obs(1.0), 0, 1.0, &obs(2.0), Status::TimeOut);
        let b: Vec<f32> = end.iter().map(|t| t.bootstrap).collect();
        assert_eq!(b, vec![0.25, 0.5]);
        // One step: Algorithm 1's targets.
        let mut n = NStep::new(1, 0.9);
        let t = n.add(&obs(0.0), 2, -1.0, &obs(1.0), Status::Running);
        assert_eq!(t[0].reward, -1.0);
        assert!((t[0].bootstrap - 0.9).abs() < 1e-7);
    }

    #[test]
    fn the_sum_tree_finds_leaves_by_mass() {
        let mut t = SumTree::new(5);
        for (i, p) in [1.0, 0.0, 2.0, 3.0, 4.0].iter().enumerate() {
            t.set(i, *p);
        }
        assert_eq!(t.total(), 10.0);
        assert_eq!(t.find(0.5), 0);
        assert_eq!(t.find(1.5), 2);
        assert_eq!(t.find(3.5), 3);
        assert_eq!(t.find(9.99), 4);
        t.set(4, 0.0);
        assert_eq!(t.total(), 6.0);
        assert_eq!(t.find(100.0), 3);
    }

    #[test]
    fn prioritised_sampling_follows_the_priorities() {
        let mut r = Replay::new(2, 4, Some(1.0));
        for k in 0..4 {
            r.push(&Transition {
                observation: obs(k as f32),
                action: 0,
                reward: 0.0,
                next_observation: obs(0.0),
                bootstrap: 0.0,
            });
        }
        // Slot 3 gets 9 times slot 0's priority; slots 1 and 2 (almost) none.
        r.update_priorities(&[0, 1, 2, 3], &[1.0 - 1e-3, 0.0, 0.0, 9.0 - 1e-3]);
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let mut counts = [0usize; 4];
        for _ in 0..200 {
            for s in r.sample(10, 1.0, &mut rng).unwrap().slots {
                counts[s] += 1;
            }
        }
        assert!(counts[1] + counts[2] < 10, "{counts:?}");
        let ratio = counts[3] as f64 / counts[0] as f64;
        assert!((7.0..12.0).contains(&ratio), "{counts:?}");
        // Importance weights: the rarely drawn slot 0 weighs most.
        let s = r.sample(64, 1.0, &mut rng).unwrap();
        let w: Vec<f32> = s.weights.to_vec1().unwrap();
        for (slot, w) in s.slots.iter().zip(w) {
            let expect = if *slot == 0 {
                1.0
            } else if *slot == 3 {
                1.0 / 9.0
            } else {
                w
            };
            assert!((w - expect).abs() < 1e-3, "slot {slot}: {w}");
        }
    }
}
