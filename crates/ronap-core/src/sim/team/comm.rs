//! What the robots of a team say to each other: each step's [`Broadcast`]s, what each robot
//! received of them ([`Inbox`]), and their delivery to the robots within range.

use super::{places_into, Team};
use crate::geometry::Point;
use crate::sim::robot::Pose;

/// What a robot broadcast at a step: received the step after by the robots within
/// `team.comm_range_px`.
#[derive(Clone, Debug, PartialEq)]
pub struct Broadcast {
    /// The sender.
    pub from: usize,
    /// Its pose when it sent.
    pub pose: Pose,
    /// Its (current) goal.
    pub goal: Point,
    /// Its policy's message (`team.message_size` floats).
    pub message: Vec<f32>,
}

/// What a robot received at the last step ([`Team::inbox`]): the broadcasts of the robots that
/// were within range when they sent, nearest first.
#[derive(Clone, Copy, Debug)]
pub struct Inbox<'a> {
    sent: &'a [Broadcast],
    places: &'a [u32],
}

impl<'a> Inbox<'a> {
    /// Number of broadcasts received.
    pub fn len(&self) -> usize {
        self.places.len()
    }

    /// Whether nothing was received.
    pub fn is_empty(&self) -> bool {
        self.places.is_empty()
    }

    /// The `i`-th nearest broadcast.
    pub fn get(&self, i: usize) -> Option<&'a Broadcast> {
        self.places.get(i).map(|&m| &self.sent[m as usize])
    }

    /// The broadcasts, nearest first.
    pub fn iter(&self) -> InboxIter<'a> {
        InboxIter {
            sent: self.sent,
            places: self.places.iter(),
        }
    }
}

impl<'a> IntoIterator for Inbox<'a> {
    type Item = &'a Broadcast;
    type IntoIter = InboxIter<'a>;

    fn into_iter(self) -> InboxIter<'a> {
        self.iter()
    }
}

/// The broadcasts of an [`Inbox`], nearest first.
#[derive(Clone, Debug)]
pub struct InboxIter<'a> {
    sent: &'a [Broadcast],
    places: std::slice::Iter<'a, u32>,
}

impl<'a> Iterator for InboxIter<'a> {
    type Item = &'a Broadcast;

    fn next(&mut self) -> Option<&'a Broadcast> {
        self.places.next().map(|&m| &self.sent[m as usize])
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.places.size_hint()
    }
}

impl ExactSizeIterator for InboxIter<'_> {}

impl std::ops::Index<usize> for Inbox<'_> {
    type Output = Broadcast;

    fn index(&self, i: usize) -> &Broadcast {
        &self.sent[self.places[i] as usize]
    }
}

impl Team {
    /// Floats in a robot's message (`team.message_size`).
    pub fn message_size(&self) -> usize {
        self.comm.message_size as usize
    }

    /// Sets robot `k`'s message for the next broadcast (the first `team.message_size` floats of
    /// `message`; the rest zeros).
    pub fn set_message(&mut self, k: usize, message: &[f32]) {
        let out = &mut self.outbox[k];
        out.fill(0.0);
        for (o, m) in out.iter_mut().zip(message) {
            *o = *m;
        }
    }

    /// What robot `k` received at the last step: the broadcasts of the robots that were within
    /// `team.comm_range_px` of it when they sent, nearest first.
    pub fn inbox(&self, k: usize) -> Inbox<'_> {
        Inbox {
            sent: &self.sent,
            places: &self.inbox[self.inbox_starts[k] as usize..self.inbox_starts[k + 1] as usize],
        }
    }

    /// Hands each robot in the scene the broadcasts `sent` from within range of where it was,
    /// nearest first, and writes the nearest `team.neighbours` into its observation; `sent` is
    /// kept until the next step.
    pub(super) fn deliver(&mut self, sent: Vec<Broadcast>) {
        let range = self.comm.comm_range_px;
        let scale = range.max(1.0);
        let slot = self.comm.slot_size();
        let k_near = self.comm.neighbours as usize;
        self.sent = sent;
        let sent = &self.sent;
        let mut s = self.scratch.take().unwrap_or_default();
        // `sent` is in robot order, and the grid holds where the senders were.
        places_into(&mut s.of, sent.iter().map(|b| b.from), self.robots.len());
        let (of, found, near) = (&s.of, &mut s.found, &mut s.heard);
        self.inbox.clear();
        for i in 0..self.robots.len() {
            self.inbox_starts[i] = self.inbox.len() as u32;
            let Some(me) = of[i].map(|m| &sent[m as usize]) else {
                continue;
            };
            let at = me.pose.position();
            // Any order: what is kept is sorted by distance, then sender.
            self.grid_before.near_any_order(at, range, found);
            near.clear();
            near.extend(
                found
                    .iter()
                    .filter(|&&j| j as usize != i)
                    .filter_map(|&j| of[j as usize])
                    .map(|m| ((sent[m as usize].pose.position() - at).norm(), m))
                    .filter(|(d, _)| *d <= range),
            );
            // Places in `sent` are in sender order.
            near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            self.inbox.extend(near.iter().map(|&(_, m)| m));
            if k_near == 0 {
                continue;
            }
            let pose = self.robots[i].pose();
            let (sin, cos) = pose.z_deg.to_radians().sin_cos();
            let slots = self.robots[i].neighbour_slots_mut();
            slots.fill(0.0);
            for (&(_, m), out) in near.iter().zip(slots.chunks_mut(slot)).take(k_near) {
                let b = &sent[m as usize];
                let d = b.pose.position() - pose.position();
                out[0] = ((d.x * cos + d.y * sin) / scale) as f32;
                out[1] = ((-d.x * sin + d.y * cos) / scale) as f32;
                out[2] = (crate::geometry::wrap_deg(b.pose.z_deg - pose.z_deg) / 360.0) as f32;
                out[3] = 1.0;
                for (o, m) in out[4..].iter_mut().zip(&b.message) {
                    *o = *m;
                }
            }
        }
        self.inbox_starts[self.robots.len()] = self.inbox.len() as u32;
        self.scratch = Some(s);
    }
}
