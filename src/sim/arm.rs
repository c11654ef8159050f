//! A planar arm in Rapier (issue 27): a fixed base and one dynamic capsule per link on revolute
//! multibody joints ([`ArmBodies`]), whose own inertia matrix (from its links' body Jacobians)
//! the tests hold to the Lagrangian's (`world::Chain::mass_matrix`), and its control in joint
//! space with its full dynamics ([`joint_control`]).
//!
//! **NADF with `D(q)`.** The laws of `control` are stated for a body of one mass. At each step
//! the arm's inertia is factored, `D(q) = L Lᵀ` (Cholesky), and the laws act in the
//! coordinates where it is the identity: the velocity `ṽ = Lᵀ q̇` (so `½ q̇ᵀ D q̇ = ½ |ṽ|²`), the
//! gradient `g̃ = L⁻¹ ∇V` (so `dV = g̃ · dq̃`), the offset `Lᵀ (q − q_T)`; the law's force `f̃`
//! (mass 1) is the joint torque `τ = L f̃` (so `τ · q̇ = f̃ · ṽ`). Then `τ = −K ∇V − B_d L M(ṽ, g̃)`
//! and, with Rapier's dynamics `D q̈ + C q̇ = τ` (Coriolis and centripetal forces left to the
//! plant, as the paper's controller does), `d/dt (K V + ½ q̇ᵀ D q̇) = −B_d ṽ · M(ṽ, g̃) ≤ 0`:
//! Proposition 1. Each joint's torque acts on its link and, reversed, on the link before it.
//!
//! **Under gravity** (Propositions 3–5) the clamp acts on the offset `Lᵀ(q − q_T)` and the
//! iterative bias is kept as a torque while `L` changes with `q`
//! ([`Bias::reexpress`](crate::control::Bias::reexpress)): eq. 48's `β` is the control fed to
//! the robot. With a joints target the field's bowl is radial in `D(q_T)`
//! ([`JointField::gradient`]), so the guidance is the spring `K_P = (K/r_c) D(q_T)` down to the
//! target and each update maps the error by `(K_P + H)⁻¹ H` (eq. 65), `H` the Jacobian of the
//! weight's torque at the target. Speeds here (`alpha`, `speed_limit`) are `|Lᵀ q̇|`,
//! `√(q̇ᵀ D q̇)`: √(2 × the kinetic energy), in √J.

use nalgebra::{DMatrix, DVector, SMatrix, SVector};
use rapier2d::prelude::*;

use crate::control::{ControlInput, Controller};
use crate::field::{JointField, angle_difference};
use crate::world::Chain;

/// A chain in Rapier: a fixed base body and one dynamic capsule per link on revolute multibody
/// joints, each link's body origin at its centre of mass (so that its body Jacobian is its
/// centre's).
pub struct ArmBodies {
    /// The fixed base.
    pub base: RigidBodyHandle,
    /// The links' bodies, from the base out.
    pub links: Vec<RigidBodyHandle>,
    /// The joints, from the base out.
    pub joints: Vec<MultibodyJointHandle>,
    /// The links' capsules, from the base out.
    pub colliders: Vec<ColliderHandle>,
}

impl ArmBodies {
    /// Inserts `chain` into `physics` at the joint angles `q` (rad). Adjacent links do not
    /// collide (their capsules overlap at the joint they share); links with no joint between
    /// them do.
    pub fn insert(physics: &mut PhysicsWorld, chain: &Chain, q: &[f64]) -> Self {
        let [bx, by] = chain.base;
        let base = physics.insert_body(RigidBodyBuilder::fixed().translation(Vector::new(bx, by)));
        // Built straight along x (every joint at 0), then turned to q by the multibody.
        let mut links = Vec::new();
        let mut joints = Vec::new();
        let mut colliders = Vec::new();
        let (mut parent, mut parent_tip) = (base, Vector::ZERO);
        let mut x = bx;
        for link in &chain.links {
            let body = RigidBodyBuilder::dynamic()
                .translation(Vector::new(x + link.com, by))
                .can_sleep(false)
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    link.mass,
                    link.inertia(),
                ));
            let handle = physics.insert_body(body);
            let (a, b) = (-link.com, link.length - link.com);
            let collider = ColliderBuilder::capsule_from_endpoints(
                Vector::new(a, 0.0),
                Vector::new(b, 0.0),
                link.radius,
            )
            .density(0.0)
            .friction(0.0)
            .restitution(0.0);
            colliders.push(physics.insert_collider(collider, Some(handle)));
            let joint = RevoluteJointBuilder::new()
                .local_anchor1(parent_tip)
                .local_anchor2(Vector::new(a, 0.0))
                .contacts_enabled(false);
            let handle_joint = physics
                .multibody_joints
                .insert(parent, handle, joint, true)
                .expect("a chain has no loop");
            links.push(handle);
            joints.push(handle_joint);
            (parent, parent_tip) = (handle, Vector::new(b, 0.0));
            x += link.length;
        }
        let arm = Self {
            base,
            links,
            joints,
            colliders,
        };
        if let Some((multibody, _)) = arm
            .joints
            .first()
            .and_then(|j| physics.multibody_joints.get_mut(*j))
        {
            // The first pass sets the multibody's degrees of freedom up.
            multibody.forward_kinematics(&physics.bodies, true);
            multibody.apply_displacements(q);
            multibody.forward_kinematics(&physics.bodies, true);
            multibody.update_rigid_bodies(&mut physics.bodies, true);
        }
        arm
    }

    /// The joint angles Rapier has, rad.
    pub fn angles(&self, physics: &PhysicsWorld) -> Vec<f64> {
        self.joints
            .iter()
            .filter_map(|&j| {
                let (multibody, link) = physics.multibody_joints.get(j)?;
                let coords = multibody.link(link)?.joint().coords();
                Some(coords.z)
            })
            .collect()
    }

    /// The joint velocities Rapier has, rad/s.
    pub fn velocities(&self, physics: &PhysicsWorld) -> Vec<f64> {
        let Some((multibody, _)) =
            (self.joints.first()).and_then(|j| physics.multibody_joints.get(*j))
        else {
            return Vec::new();
        };
        let v = multibody.generalized_velocity();
        let offset = v.len() - self.joints.len();
        (0..self.joints.len()).map(|i| v[offset + i]).collect()
    }

    /// Resets the links' forces and applies the joint torques `tau` (N·m): joint `i`'s on link
    /// `i`, and reversed on link `i − 1` (the base takes the first's reaction).
    pub fn apply_torques(&self, physics: &mut PhysicsWorld, tau: &[f64]) {
        for &h in &self.links {
            let body = &mut physics.bodies[h];
            body.reset_forces(false);
            body.reset_torques(false);
        }
        for (i, &t) in tau.iter().enumerate() {
            physics.bodies[self.links[i]].add_torque(t, true);
            if i > 0 {
                physics.bodies[self.links[i - 1]].add_torque(-t, true);
            }
        }
    }

    /// The inertia matrix Rapier's multibody has at its current configuration:
    /// `Σ_i J_iᵀ diag(m_i, m_i, I_i) J_i` over its links' body Jacobians (refreshed by a forward
    /// kinematics pass), kg·m².
    pub fn mass_matrix(&self, physics: &mut PhysicsWorld) -> DMatrix<f64> {
        let n = self.joints.len();
        let mut d = DMatrix::zeros(n, n);
        // Rapier folds the mass properties in at its next step; the matrix is read now.
        for &h in &self.links {
            physics.bodies[h].recompute_mass_properties_from_colliders(&physics.colliders);
        }
        let Some((multibody, _)) =
            (self.joints.first()).and_then(|j| physics.multibody_joints.get_mut(*j))
        else {
            return d;
        };
        multibody.forward_kinematics(&physics.bodies, true);
        for link in multibody.links() {
            let body = &physics.bodies[link.rigid_body_handle()];
            let (m, inertia) = (
                body.mass(),
                body.mass_properties().local_mprops.principal_inertia(),
            );
            if m == 0.0 {
                continue;
            }
            let jac = multibody.body_jacobian(link.link_id());
            let dofs = jac.ncols().min(n);
            let offset = jac.ncols() - dofs;
            for a in 0..dofs {
                for b in 0..dofs {
                    let (ja, jb) = (
                        |r: usize| jac[(r, offset + a)],
                        |r: usize| jac[(r, offset + b)],
                    );
                    d[(a, b)] += m * (ja(0) * jb(0) + ja(1) * jb(1)) + inertia * ja(2) * jb(2);
                }
            }
        }
        d
    }
}

/// Where an arm's controller takes its offset from the target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Aim<'a> {
    /// Target joint angles, rad: the offset is `q − q_T` (wrapped).
    Joints(&'a [f64]),
    /// A target point for the tip, m: the offset is the least-squares joint displacement that
    /// would take the tip there to first order, `J⁺ (tip − p)` (so that the laws that need a
    /// distance, the guidance's taper, the clamp, the brake, have one).
    Point([f64; 2]),
}

/// One control step of an arm at joint angles `q` and velocities `qdot` (rad, rad/s) towards
/// `aim`:
/// the plane's `controller` (for a body of mass 1) in the coordinates where `D(q)` is the
/// identity (see the module), the guidance from `field`. `frame` is the factor `L` of the
/// last step's `D(q) = LLᵀ` (`None` at the first step), which this step replaces with its own:
/// the bias is kept as a torque across the change. Returns the joint torques, N·m, and
/// whether the controller's bias was updated (a settling instant).
pub fn joint_control<const N: usize>(
    (controller, field, chain): (&mut Controller<N>, &JointField, &Chain),
    (q, qdot, frame): (&[f64], &[f64], &mut Option<DMatrix<f64>>),
    aim: Aim,
    (dt, touching): (f64, bool),
) -> (Vec<f64>, bool) {
    let d = chain.mass_matrix(q);
    let Some(cholesky) = d.cholesky() else {
        return (vec![0.0; N], false);
    };
    let l = cholesky.l();
    // The bias is a torque: it keeps it as the coordinates move (`Bias::reexpress`).
    if let (Some(bias), Some(previous)) = (&mut controller.bias, frame.as_ref())
        && let Some(m) = l.solve_lower_triangular(previous)
    {
        bias.reexpress(&SMatrix::<f64, N, N>::from_iterator(m.iter().copied()));
    }
    *frame = Some(l.clone());
    let lt = l.transpose();
    let v = &lt * DVector::from_column_slice(qdot);
    let gradient = field.gradient(q).and_then(|g| l.solve_lower_triangular(&g));
    let error = match aim {
        Aim::Joints(t) => DVector::from_iterator(N, (0..N).map(|i| angle_difference(q[i], t[i]))),
        Aim::Point(p) => {
            let tip = chain.tip(q);
            let e = nalgebra::Vector2::new(tip[0] - p[0], tip[1] - p[1]);
            let j = chain.tip_jacobian(q);
            j.pseudo_inverse(1e-9)
                .map_or(DVector::zeros(N), |pinv| pinv * e)
        }
    };
    let offset = &lt * error;
    let fixed = |x: &DVector<f64>| SVector::<f64, N>::from_iterator(x.iter().copied());
    let input = ControlInput {
        offset: fixed(&offset),
        velocity: fixed(&v),
        gradient: gradient.as_ref().map(fixed),
        curvature: None,
        dt,
        touching,
        reference_velocity: None,
    };
    let out = controller.step(&input);
    let tau = l * DVector::from_iterator(N, out.force.iter().copied());
    (tau.iter().copied().collect(), out.bias_updated)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::{Guidance, GuidanceMode, Nadf};
    use crate::field::{JointAxis, JointMask, JointTarget};
    use crate::world::arm::tests::chain;
    use crate::world::{Wall, wall_shape};

    /// Rapier's multibody, posed at the same joint angles, has the Lagrangian's joints, and its
    /// inertia matrix is the Lagrangian's to the test's tolerance, at configurations spread over
    /// the joint space.
    #[test]
    fn rapier_and_the_lagrangian_agree_on_the_inertia_matrix() {
        let c = chain();
        for (n, q) in [
            [0.0, 0.0, 0.0],
            [0.4, -1.1, 2.0],
            [-2.5, 0.7, -0.3],
            [3.0, 3.0, 1.0],
        ]
        .iter()
        .enumerate()
        {
            let mut physics = PhysicsWorld::default();
            let arm = ArmBodies::insert(&mut physics, &c, q);
            let angles = arm.angles(&physics);
            for (a, b) in angles.iter().zip(q) {
                assert!((a - b).abs() < 1e-5, "case {n}: angles {angles:?} vs {q:?}");
            }
            // Each link's body sits at the Lagrangian's centre of mass.
            for (h, p) in arm.links.iter().zip(c.centres(q)) {
                let t = physics.bodies[*h].translation();
                assert!(
                    (t.x - p[0]).abs() < 1e-5 && (t.y - p[1]).abs() < 1e-5,
                    "case {n}: {t:?} vs {p:?}"
                );
            }
            let (rapier, lagrange) = (arm.mass_matrix(&mut physics), c.mass_matrix(q));
            let worst = (rapier.clone() - lagrange.clone()).amax();
            println!(
                "case {n}: largest difference {worst:e} of {}",
                lagrange.amax()
            );
            assert!(
                worst < 1e-5 * lagrange.amax(),
                "case {n}:\nRapier {rapier}\nLagrangian {lagrange}"
            );
        }
    }

    /// Proposition 1 with the arm's own `D(q)`: a three-link arm turning its first joint by
    /// 2.3 rad past a post, without gravity, under the paper's `τ = −K∇V − B_d L M`, simulated by
    /// Rapier's multibody (Coriolis and centripetal terms included), never lets
    /// `K·V + ½ q̇ᵀ D q̇` grow outside the target set and its bowl by more than integration
    /// error (Rapier's step), ends at the target joints (the bowl leads it there; measured
    /// 1.3e-5 rad after 30 s, having crawled the field's shallow part for 19 s and swung once
    /// through the target), and touches nothing.
    #[test]
    fn the_energy_of_an_arm_never_increases() {
        let c = chain();
        let post = wall_shape(&Wall::Disc {
            center: [2.1, 3.0],
            radius: 0.15,
        })
        .unwrap();
        let walls = vec![post];
        let axes = [
            JointAxis {
                cells: 64,
                limits: None,
            },
            JointAxis {
                cells: 64,
                limits: None,
            },
            JointAxis {
                cells: 64,
                limits: None,
            },
        ];
        let bounds = ([-1.5, -1.0], [3.5, 5.0]);
        let mask = JointMask::build(&c, &axes, &walls, bounds);
        let (start, goal) = ([-0.4, 0.3, 0.2], [1.9, 0.4, -0.3]);
        let target = JointTarget::Joints {
            q: goal.to_vec(),
            radius: 0.25,
        };
        let field = JointField::solve(&c, mask, (&start, &target), 1e-12, "arm").unwrap();
        let dt = 0.002;
        let mut physics = super::super::physics::empty_world(dt, [0.0, 0.0]);
        super::super::physics::insert_walls(&mut physics, &walls);
        let arm = ArmBodies::insert(&mut physics, &c, &start);
        let k = 20.0;
        let laws: Vec<Box<dyn crate::control::ControlLaw<3>>> = vec![
            Box::new(Guidance {
                k,
                mode: GuidanceMode::Gradient,
            }),
            Box::new(Nadf { b_d: 5.0 }),
        ];
        let mut controller = Controller::<3>::new(laws, 1.0);
        let energy = |physics: &PhysicsWorld| {
            let (q, v) = (arm.angles(physics), arm.velocities(physics));
            let d = c.mass_matrix(&q);
            let v = DVector::from_vec(v);
            (
                k * field.potential(&q) + 0.5 * (v.transpose() * &d * &v)[(0, 0)],
                q,
            )
        };
        let (e0, _) = energy(&physics);
        let mut last = e0;
        let (mut worst, mut checked, mut closest) = (0.0_f64, 0, f64::INFINITY);
        for _ in 0..15_000 {
            let (q, v) = (arm.angles(&physics), arm.velocities(&physics));
            let (tau, _) = joint_control(
                (&mut controller, &field, &c),
                (&q, &v, &mut None),
                Aim::Joints(&goal),
                (dt, false),
            );
            arm.apply_torques(&mut physics, &tau);
            physics.step();
            let (e, q) = energy(&physics);
            // No link touches the post (it is a capsule of its radius around its segment).
            for (link, s) in c.links.iter().zip(c.joints(&q).windows(2)) {
                let d = crate::field::segment_distance([s[0], s[1]], [[2.1, 3.0], [2.1, 3.0]]);
                closest = closest.min(d - 0.15 - link.radius);
            }
            // In the target set, and in the bowl around it, where the guidance is the
            // target's spring rather than −K∇V of the solved V (`JointField::gradient`).
            let to_goal = (q.iter().zip(goal))
                .map(|(a, b)| angle_difference(*a, b).powi(2))
                .sum::<f64>()
                .sqrt();
            let inside = to_goal < field.rim()
                || field
                    .mask
                    .cell_of(&q)
                    .is_some_and(|cell| field.w.value(cell) == 1.0);
            if !inside {
                worst = worst.max(e - last);
                checked += 1;
            }
            last = e;
        }
        let q = arm.angles(&physics);
        let error: f64 = q
            .iter()
            .zip(goal)
            .map(|(a, b)| angle_difference(*a, b).powi(2))
            .sum::<f64>()
            .sqrt();
        println!(
            "{checked} steps checked, largest rise {worst:e} of {e0}, {last} left; final joint error {error} rad; closest to the post {closest} m"
        );
        assert!(closest > 0.0, "a link touched the post");
        assert!(checked > 500, "{checked}");
        assert!(
            worst <= 1e-3 * e0,
            "the energy rose by {worst} in a step (of {e0})"
        );
        assert!(error < 1e-3, "ended at {q:?}");
    }
}
