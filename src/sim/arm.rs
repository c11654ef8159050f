//! A planar arm in Rapier (issue 27, first part): a fixed base and one dynamic capsule per link
//! on revolute multibody joints ([`ArmBodies`]), whose own inertia matrix (from its links' body
//! Jacobians) the tests hold to the Lagrangian's (`world::Chain::mass_matrix`).

use nalgebra::DMatrix;
use rapier2d::prelude::*;

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
}

impl ArmBodies {
    /// Inserts `chain` into `physics` at the joint angles `q` (rad). Adjacent links do not
    /// collide (their capsules overlap at the joint they share); links with no joint between
    /// them do.
    pub fn insert(physics: &mut PhysicsWorld, chain: &Chain, q: &[f64]) -> Self {
        let [bx, by] = chain.base;
        let base = physics
            .insert_body(RigidBodyBuilder::fixed().translation(Vector::new(bx as f32, by as f32)));
        // Built straight along x (every joint at 0), then turned to q by the multibody.
        let mut links = Vec::new();
        let mut joints = Vec::new();
        let (mut parent, mut parent_tip) = (base, Vector::ZERO);
        let mut x = bx;
        for link in &chain.links {
            let body = RigidBodyBuilder::dynamic()
                .translation(Vector::new((x + link.com) as f32, by as f32))
                .can_sleep(false)
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    link.mass as f32,
                    link.inertia() as f32,
                ));
            let handle = physics.insert_body(body);
            let (a, b) = (-link.com as f32, (link.length - link.com) as f32);
            let collider = ColliderBuilder::capsule_from_endpoints(
                Vector::new(a, 0.0),
                Vector::new(b, 0.0),
                link.radius as f32,
            )
            .density(0.0)
            .friction(0.0)
            .restitution(0.0);
            physics.insert_collider(collider, Some(handle));
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
        };
        if let Some((multibody, _)) = arm
            .joints
            .first()
            .and_then(|j| physics.multibody_joints.get_mut(*j))
        {
            // The first pass sets the multibody's degrees of freedom up.
            multibody.forward_kinematics(&physics.bodies, true);
            let turn: Vec<f32> = q.iter().map(|&a| a as f32).collect();
            multibody.apply_displacements(&turn);
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
                Some(f64::from(coords.z))
            })
            .collect()
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
                f64::from(body.mass()),
                f64::from(body.mass_properties().local_mprops.principal_inertia()),
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
                        |r: usize| f64::from(jac[(r, offset + a)]),
                        |r: usize| f64::from(jac[(r, offset + b)]),
                    );
                    d[(a, b)] += m * (ja(0) * jb(0) + ja(1) * jb(1)) + inertia * ja(2) * jb(2);
                }
            }
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::arm::tests::chain;

    /// Rapier's multibody, posed at the same joint angles, has the Lagrangian's joints, and its
    /// inertia matrix is the Lagrangian's to f32 precision, at configurations spread over the
    /// joint space.
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
                    (f64::from(t.x) - p[0]).abs() < 1e-5 && (f64::from(t.y) - p[1]).abs() < 1e-5,
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
}
