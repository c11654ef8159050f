//! An arm's run (`[[arms]]`, issue 27): its joint-space field, its Rapier multibody, the control
//! of [`super::arm::joint_control`] every step, and what it reports: whether it ended in its
//! target set and when it entered it for good, the joint and tip errors, contacts of any link,
//! the links' clearance, and the torques.

use std::collections::HashSet;
use std::time::{Duration, Instant};

use rapier2d::prelude::*;
use serde::Serialize;

use super::CONTACT_TOLERANCE;
use super::arm::{Aim, ArmBodies, joint_control};
use crate::control::Controller;
use crate::field::{
    FieldError, JointAxis, JointField, JointMask, JointTarget, angle_difference, segment_distance,
};
use crate::world::{ArmSettings, Chain, WallShape, World};

/// The controller of an arm of two or three joints.
enum ArmController {
    Two(Controller<2>),
    Three(Controller<3>),
}

/// One arm in a running simulation.
pub struct ArmRun {
    /// The arm as the world file describes it.
    pub settings: ArmSettings,
    /// Its chain.
    pub chain: Chain,
    /// Its joint-space field.
    pub field: JointField,
    /// Its bodies in Rapier.
    pub bodies: ArmBodies,
    /// Wall-clock time of its mask.
    pub mask_time: Duration,
    controller: ArmController,
    /// The factor `L` of the last control step's `D(q) = LLᵀ` (see [`joint_control`]).
    frame: Option<nalgebra::DMatrix<f64>>,
    touching: HashSet<ColliderHandle>,
    state: ArmState,
    contacts: usize,
    min_clearance: f64,
    peak_torque: f64,
    control_variation: f64,
    entered_at: Option<f64>,
    /// The time at the start of the current step, s.
    time: f64,
    /// Each update of the bias β: when (s) and the joint error `q − q_T` then (rad; empty for a
    /// target point).
    pub bias_updates: Vec<(f64, Vec<f64>)>,
}

/// An arm's state after a step.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmState {
    /// Joint angles, rad.
    pub q: Vec<f64>,
    /// Joint velocities, rad/s.
    pub qdot: Vec<f64>,
    /// The joint torques during the step, N·m.
    pub torque: Vec<f64>,
    /// The joints' positions and the tip's, m.
    pub joints: Vec<[f64; 2]>,
    /// Whether the configuration is in the target set.
    pub in_target: bool,
    /// Contacts that started in this step, as messages.
    pub events: Vec<String>,
}

crate::measured! {
    /// An arm's summary, with the key names of `--json`.
    #[derive(Debug, Clone, PartialEq, Serialize)]
    pub struct ArmSummary {
        /// The arm's name.
        pub name: String,
        /// Whether it ends in its target set.
        pub reached: bool [column("reached")],
        /// When it last entered its target set, s (`None` if it ends outside).
        pub settling_time: Option<f64> [unit("s"), column("settle_s"), missing("never")],
        /// The final `|q − q_T|` (wrapped), rad; `None` for a target point.
        pub final_joint_error: Option<f64> [unit("rad"), column("joint_rad"), missing("a point")],
        /// The final distance of the tip to the target point (or to the target joints' tip), m.
        pub final_tip_error: f64 [unit("m"), column("tip_m")],
        /// Contact starts of any link, with anything.
        pub contacts: usize [column("contacts")],
        /// The smallest distance from a link's capsule to a wall over the run, m.
        pub min_clearance: f64 [unit("m"), column("clear_m")],
        /// The largest joint torque, N·m.
        pub peak_torque: f64 [unit("N·m"), digits(2), column("peak_Nm")],
        /// `Σ_k |τ_k − τ_{k−1}|` over the steps, N·m.
        pub control_variation: f64 [unit("N·m"), digits(2), column("var_Nm")],
        /// Updates of the iterative bias β (eq. 49); zero without the bias option.
        pub bias_updates: usize [column("updates")],
    }
}

/// The joint-space field of `settings` (an arm of `world`) among `walls`, and how long its mask
/// took: the mask of its links, then the field towards its target (an intractable target is an
/// error before the solve).
pub fn solve_field(
    world: &World,
    settings: &ArmSettings,
    walls: &[WallShape],
) -> Result<(JointField, Duration), FieldError> {
    let chain = settings.chain();
    let axes: Vec<JointAxis> = (settings.links.iter())
        .map(|l| JointAxis {
            cells: settings.cells(),
            limits: l.limits,
        })
        .collect();
    let started = Instant::now();
    let mask = JointMask::build(&chain, &axes, walls, world.bounds());
    let mask_time = started.elapsed();
    let target = match (&settings.target_joints, settings.target_point) {
        (Some(q), _) => JointTarget::Joints {
            q: q.clone(),
            radius: settings.target_radius,
        },
        (None, Some(point)) => JointTarget::Point {
            point,
            radius: settings.target_radius,
        },
        (None, None) => unreachable!("validated: one target"),
    };
    let field = JointField::solve(
        &chain,
        mask,
        (&settings.start, &target),
        world.field.tolerance,
        &settings.name,
    )?;
    Ok((field, mask_time))
}

impl ArmRun {
    /// Builds arm `index` of `world` into `physics`: its mask and field (an intractable target
    /// is an error before the solve), its bodies at the start.
    pub(super) fn new(
        world: &World,
        index: usize,
        physics: &mut PhysicsWorld,
        walls: &[WallShape],
    ) -> Result<Self, FieldError> {
        let settings = world.arms[index].clone();
        let chain = settings.chain();
        let (field, mask_time) = solve_field(world, &settings, walls)?;
        let bodies = ArmBodies::insert(physics, &chain, &settings.start);
        let s = &settings.controller;
        let guidance = world.field.guidance;
        // The laws act where the inertia is the identity: a body of mass 1.
        let controller = match chain.links.len() {
            2 => ArmController::Two(Controller::from_settings(s, guidance, 1.0)),
            _ => ArmController::Three(Controller::from_settings(s, guidance, 1.0)),
        };
        let state = ArmState {
            q: settings.start.clone(),
            qdot: vec![0.0; chain.links.len()],
            torque: vec![0.0; chain.links.len()],
            joints: chain.joints(&settings.start),
            in_target: false,
            events: Vec::new(),
        };
        let mut run = Self {
            settings,
            chain,
            field,
            bodies,
            mask_time,
            controller,
            frame: None,
            touching: HashSet::new(),
            state,
            contacts: 0,
            min_clearance: f64::INFINITY,
            peak_torque: 0.0,
            control_variation: 0.0,
            entered_at: None,
            time: 0.0,
            bias_updates: Vec::new(),
        };
        run.state.in_target = run.in_target(&run.settings.start.clone());
        if run.state.in_target {
            run.entered_at = Some(0.0);
        }
        Ok(run)
    }

    /// Its state after the last step.
    pub fn state(&self) -> &ArmState {
        &self.state
    }

    /// Whether `q` is in the target set.
    fn in_target(&self, q: &[f64]) -> bool {
        match (&self.settings.target_joints, self.settings.target_point) {
            (Some(t), _) => self.joint_error(q, t) <= self.settings.target_radius,
            (None, Some(p)) => {
                let tip = self.chain.tip(q);
                (tip[0] - p[0]).hypot(tip[1] - p[1]) <= self.settings.target_radius
            }
            _ => false,
        }
    }

    fn joint_error(&self, q: &[f64], t: &[f64]) -> f64 {
        (q.iter().zip(t))
            .map(|(a, b)| angle_difference(*a, *b).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// Computes and applies the joint torques for a step of `dt` (s).
    pub(super) fn apply(&mut self, physics: &mut PhysicsWorld, dt: f64) {
        let (q, qdot) = (self.bodies.angles(physics), self.bodies.velocities(physics));
        let finite = q.iter().chain(&qdot).all(|c| c.is_finite());
        let aim = match (&self.settings.target_joints, self.settings.target_point) {
            (Some(t), _) => Aim::Joints(t),
            (None, Some(p)) => Aim::Point(p),
            (None, None) => unreachable!("validated: one target"),
        };
        let touching = !self.touching.is_empty();
        let (tau, bias_updated) = if !finite {
            (vec![0.0; q.len()], false)
        } else {
            match &mut self.controller {
                ArmController::Two(c) => joint_control(
                    (c, &self.field, &self.chain),
                    (&q, &qdot, &mut self.frame),
                    aim,
                    (dt, touching),
                ),
                ArmController::Three(c) => joint_control(
                    (c, &self.field, &self.chain),
                    (&q, &qdot, &mut self.frame),
                    aim,
                    (dt, touching),
                ),
            }
        };
        let tau: Vec<f64> = tau
            .into_iter()
            .map(|t| if t.is_finite() { t } else { 0.0 })
            .collect();
        if bias_updated {
            let error = match &self.settings.target_joints {
                Some(t) => (q.iter().zip(t))
                    .map(|(a, b)| angle_difference(*a, *b))
                    .collect(),
                None => Vec::new(),
            };
            self.bias_updates.push((self.time, error));
        }
        self.bodies.apply_torques(physics, &tau);
        let size = tau.iter().fold(0.0f64, |m, t| m.max(t.abs()));
        self.peak_torque = self.peak_torque.max(size);
        let change: f64 = (tau.iter().zip(&self.state.torque))
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        self.control_variation += change;
        self.state.torque = tau;
    }

    /// After Rapier's step that ended at `time` (s): reads the state, counts contact starts,
    /// measures the links' clearance from `walls`.
    pub(super) fn observe(&mut self, physics: &PhysicsWorld, time: f64, walls: &[WallShape]) {
        let (q, qdot) = (self.bodies.angles(physics), self.bodies.velocities(physics));
        let joints = self.chain.joints(&q);
        let mut events = Vec::new();
        // Contacts of any link with anything (adjacent links do not collide).
        let mut now = HashSet::new();
        for &collider in &self.bodies.colliders {
            for pair in physics.narrow_phase.contact_pairs_with(collider) {
                if !pair.has_any_active_contact() {
                    continue;
                }
                let other = if pair.collider1 == collider {
                    pair.collider2
                } else {
                    pair.collider1
                };
                let touches = (pair.manifolds().iter())
                    .any(|m| m.points.iter().any(|c| c.dist <= CONTACT_TOLERANCE));
                if touches {
                    now.insert((collider, other));
                }
            }
        }
        let started = now
            .iter()
            .filter(|(_, other)| !self.touching.contains(other))
            .count();
        self.touching = now.into_iter().map(|(_, other)| other).collect();
        if started > 0 {
            self.contacts += started;
            events.push(format!(
                "contact at t = {time:.3} s, joints {q:.3?} ({} collider(s) touched now)",
                self.touching.len()
            ));
        }
        for (link, s) in self.chain.links.iter().zip(joints.windows(2)) {
            let segment = parry2d::shape::Segment::new(
                Vector::new(s[0][0], s[0][1]),
                Vector::new(s[1][0], s[1][1]),
            );
            let mid = [(s[0][0] + s[1][0]) / 2.0, (s[0][1] + s[1][1]) / 2.0];
            let half = 0.5 * segment_distance([s[0], s[1]], [s[0], s[0]]);
            for w in walls {
                if w.distance_bound(mid[0], mid[1]) - half - link.radius >= self.min_clearance {
                    continue;
                }
                if let Ok(d) =
                    parry2d::query::distance(&Pose::IDENTITY, &segment, &w.pose, w.shape.as_ref())
                {
                    self.min_clearance = self.min_clearance.min(d.distance - link.radius);
                }
            }
        }
        self.time = time;
        let in_target = self.in_target(&q);
        if in_target && !self.state.in_target {
            self.entered_at = Some(time);
        }
        self.state = ArmState {
            q,
            qdot,
            torque: std::mem::take(&mut self.state.torque),
            joints,
            in_target,
            events,
        };
    }

    /// Its summary so far.
    pub fn summary(&self) -> ArmSummary {
        let q = &self.state.q;
        let tip = self.chain.tip(q);
        let target_tip = match (&self.settings.target_joints, self.settings.target_point) {
            (Some(t), _) => self.chain.tip(t),
            (None, Some(p)) => p,
            _ => tip,
        };
        ArmSummary {
            name: self.settings.name.clone(),
            reached: self.state.in_target,
            settling_time: self.state.in_target.then_some(self.entered_at).flatten(),
            final_joint_error: (self.settings.target_joints.as_ref())
                .map(|t| self.joint_error(q, t)),
            final_tip_error: (tip[0] - target_tip[0]).hypot(tip[1] - target_tip[1]),
            contacts: self.contacts,
            min_clearance: if self.min_clearance.is_finite() {
                self.min_clearance.max(0.0)
            } else {
                0.0
            },
            peak_torque: self.peak_torque,
            control_variation: self.control_variation,
            bias_updates: self.bias_updates.len(),
        }
    }
}
