//! A planar arm as a world describes it (issue 27, first part): a serial chain of links on
//! revolute joints from a fixed base ([`Chain`]), its kinematics and its inertia matrix `D(q)`
//! from the Lagrangian. `sim::arm` puts it in Rapier.
//!
//! Joint `i` turns link `i` relative to link `i − 1` (the first relative to the world's x axis):
//! link `i` points along `φ_i = q_1 + … + q_i`. Link `i` has its mass `m_i` at `c_i` along it
//! from its joint and the moment of inertia of a uniform rod, `m_i L_i² / 12`, about that point
//! (its capsule's own mass distribution differs by the caps; the rod is what the Lagrangian and
//! Rapier are both given).
//!
//! **The Lagrangian.** The centre of mass of link `i` is
//! `p_i = b + Σ_{j<i} L_j u(φ_j) + c_i u(φ_i)` with `u(φ) = (cos φ, sin φ)`, so
//! `∂p_i/∂q_k = Σ_{k≤j<i} L_j u⊥(φ_j) + c_i u⊥(φ_i)` for `k ≤ i` (0 beyond), and its angular
//! velocity is `Σ_{k≤i} q̇_k`. The kinetic energy `½ q̇ᵀ D q̇` gives
//! `D = Σ_i m_i J_iᵀ J_i + I_i j_iᵀ j_i` (the paper's Proposition 1 with `D(x)`).

use nalgebra::DMatrix;

/// One link of a planar arm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    /// Length from its joint to the next one (or its tip), m.
    pub length: f64,
    /// Mass, kg.
    pub mass: f64,
    /// Distance of its centre of mass from its joint along it, m (the middle by default).
    pub com: f64,
    /// Radius of its capsule, m.
    pub radius: f64,
}

impl Link {
    /// A link of `length` m and `mass` kg with its centre of mass at its middle, a capsule of
    /// `radius` m.
    ///
    /// ```
    /// let link = nadf::world::Link::rod(0.8, 1.0, 0.05);
    /// assert_eq!(link.com, 0.4);
    /// ```
    pub fn rod(length: f64, mass: f64, radius: f64) -> Self {
        Self {
            length,
            mass,
            com: 0.5 * length,
            radius,
        }
    }

    /// Its moment of inertia about its centre of mass, kg·m²: a uniform rod's.
    pub fn inertia(&self) -> f64 {
        self.mass * self.length * self.length / 12.0
    }
}

/// A planar serial chain from a fixed base.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// The first joint's position, m.
    pub base: [f64; 2],
    /// The links, from the base out.
    pub links: Vec<Link>,
}

/// `(cos φ, sin φ)`.
fn u(phi: f64) -> [f64; 2] {
    [phi.cos(), phi.sin()]
}

impl Chain {
    /// The absolute angle of each link, rad: `φ_i = q_1 + … + q_i`.
    pub fn angles(&self, q: &[f64]) -> Vec<f64> {
        q.iter()
            .scan(0.0, |phi, qi| {
                *phi += qi;
                Some(*phi)
            })
            .collect()
    }

    /// Each joint's position and the tip's, m: `links.len() + 1` points.
    pub fn joints(&self, q: &[f64]) -> Vec<[f64; 2]> {
        let mut points = vec![self.base];
        for (link, phi) in self.links.iter().zip(self.angles(q)) {
            let [x, y] = *points.last().expect("the base");
            let d = u(phi);
            points.push([x + link.length * d[0], y + link.length * d[1]]);
        }
        points
    }

    /// The tip (the end of the last link), m.
    pub fn tip(&self, q: &[f64]) -> [f64; 2] {
        *self.joints(q).last().expect("the base")
    }

    /// The tip's Jacobian `∂tip/∂q` (2 × joints), m/rad.
    pub fn tip_jacobian(&self, q: &[f64]) -> DMatrix<f64> {
        let phi = self.angles(q);
        let n = self.links.len();
        let mut j = DMatrix::zeros(2, n);
        for k in 0..n {
            for (link, angle) in self.links.iter().zip(&phi).skip(k) {
                j[(0, k)] -= link.length * angle.sin();
                j[(1, k)] += link.length * angle.cos();
            }
        }
        j
    }

    /// Each link's centre of mass, m.
    pub fn centres(&self, q: &[f64]) -> Vec<[f64; 2]> {
        let joints = self.joints(q);
        (self.links.iter().zip(self.angles(q)).enumerate())
            .map(|(i, (link, phi))| {
                let d = u(phi);
                [
                    joints[i][0] + link.com * d[0],
                    joints[i][1] + link.com * d[1],
                ]
            })
            .collect()
    }

    /// The inertia matrix `D(q)` from the Lagrangian (see the module), kg·m².
    pub fn mass_matrix(&self, q: &[f64]) -> DMatrix<f64> {
        let n = self.links.len();
        let phi = self.angles(q);
        let mut d = DMatrix::zeros(n, n);
        for (i, link) in self.links.iter().enumerate() {
            // ∂p_i/∂q_k: the perpendiculars of the link vectors from joint k out to link i's
            // centre of mass.
            let mut jac = vec![[0.0; 2]; n];
            for (k, column) in jac.iter_mut().enumerate().take(i + 1) {
                for (j, angle) in phi.iter().enumerate().take(i + 1).skip(k) {
                    let length = if j == i {
                        link.com
                    } else {
                        self.links[j].length
                    };
                    let [c, s] = u(*angle);
                    column[0] -= length * s;
                    column[1] += length * c;
                }
            }
            for a in 0..=i {
                for b in 0..=i {
                    let linear = jac[a][0] * jac[b][0] + jac[a][1] * jac[b][1];
                    d[(a, b)] += link.mass * linear + link.inertia();
                }
            }
        }
        d
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A three-link arm of unequal links.
    pub(crate) fn chain() -> Chain {
        Chain {
            base: [1.0, 2.0],
            links: vec![
                Link {
                    length: 1.0,
                    mass: 2.0,
                    com: 0.5,
                    radius: 0.05,
                },
                Link {
                    length: 0.8,
                    mass: 1.5,
                    com: 0.3,
                    radius: 0.05,
                },
                Link {
                    length: 0.5,
                    mass: 0.7,
                    com: 0.25,
                    radius: 0.04,
                },
            ],
        }
    }

    /// The textbook two-link `D(q)`: `D11 = I1 + I2 + m1 c1² + m2 (L1² + c2² + 2 L1 c2 cos q2)`,
    /// `D12 = I2 + m2 (c2² + L1 c2 cos q2)`, `D22 = I2 + m2 c2²`.
    #[test]
    fn two_links_give_the_textbook_inertia_matrix() {
        let mut c = chain();
        c.links.truncate(2);
        let q = [0.4, -1.1];
        let d = c.mass_matrix(&q);
        let ([l1, c1], [c2, m2], m1) = ([1.0, 0.5], [0.3, 1.5], 2.0);
        let (i1, i2) = (c.links[0].inertia(), c.links[1].inertia());
        let cos = q[1].cos();
        let d11 = i1 + i2 + m1 * c1 * c1 + m2 * (l1 * l1 + c2 * c2 + 2.0 * l1 * c2 * cos);
        let d12 = i2 + m2 * (c2 * c2 + l1 * c2 * cos);
        let d22 = i2 + m2 * c2 * c2;
        for (got, want) in [
            (d[(0, 0)], d11),
            (d[(0, 1)], d12),
            (d[(1, 0)], d12),
            (d[(1, 1)], d22),
        ] {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }
}
