//! Numerical faults of a run, watched step by step: the guidance vanishing or reversing (a
//! critical point such as a saddle, a flat region, a position off the field), a control force Rapier cannot take, a body driven
//! into a wall or out of the box, a non-finite state. None of them may crash a run or put a NaN
//! into Rapier; each is counted in the summary and its start is logged as an event.

use nalgebra::Vector2;

use crate::control::unit;
use crate::field::{GuidanceField, HarmonicField};
use crate::metrics::Faults;

/// How deep a body may overlap a wall before it counts as pushed into it, m. Rapier's solver
/// itself allows about 1 mm.
pub const PENETRATION_TOLERANCE: f64 = 0.01;

/// Below this change of `W` across one cell, relative to `W`, the field is flat to working
/// precision there: a critical point (where `∇V = 0`) or a region the solver left flat.
pub const FLAT_RELATIVE_CHANGE: f64 = 1e-9;

/// One agent's faults so far, and which are ongoing (to log each start once).
#[derive(Debug, Clone, Default)]
pub struct FaultMonitor {
    /// The counts.
    pub faults: Faults,
    last_direction: Option<Vector2<f64>>,
    guidance_lost: bool,
    penetrating: bool,
    outside: bool,
}

/// What the monitor sees of an agent after a step.
pub struct Observation<'a> {
    /// The agent's field.
    pub field: &'a GuidanceField,
    /// Position, m.
    pub position: Vector2<f64>,
    /// Signed distance from the disc to the nearest wall, m (negative when overlapping).
    pub signed_clearance: f64,
    /// The world's box, its lower-left and upper-right corners, m.
    pub bounds: ([f64; 2], [f64; 2]),
    /// Whether the order of way among agents rules the field (`field/yielding.rs`): taking the
    /// agent out of another's way (flat where it waits), or just changed by the rule (it may
    /// turn about). Neither is a critical point of a field: no fault.
    pub giving_way: bool,
    /// Whether its field was solved anew in this step: the last step's direction came from
    /// another field, so a reversal from it is the new field's choice of way (round the other
    /// side of a neighbour, back from a wall just sensed), not a critical point.
    pub replanned: bool,
}

impl FaultMonitor {
    /// Counts a control force that Rapier could not take (zero was applied instead).
    pub fn rejected_force(&mut self) -> Option<String> {
        self.faults.rejected_forces += 1;
        (self.faults.rejected_forces == 1).then(|| {
            "the control force was not finite in f32 (the recording's precision): zero applied \
             instead"
                .to_string()
        })
    }

    /// Records that Rapier's state of the agent became non-finite; it is frozen from now on.
    pub fn non_finite_state(&mut self) -> Option<String> {
        let first = !self.faults.non_finite_state;
        self.faults.non_finite_state = true;
        first.then(|| "the body's state became non-finite: it is frozen from now on".to_string())
    }

    /// Checks the agent after a step; returns the faults that start now, as messages.
    pub fn observe(&mut self, o: &Observation) -> Vec<String> {
        let mut events = Vec::new();
        let p: [f64; 2] = o.position.into();
        let cell = o.field.cell();
        // The target's own neighbourhood: two cells, or the rim of a harmonic field's target
        // disc (inside it the guidance is the bowl to the target point, and the direction
        // turns about as the body settles there).
        let near = o
            .field
            .harmonic()
            .map_or(0.0, HarmonicField::rim)
            .max(2.0 * cell);
        let near_target = (o.position - Vector2::from(o.field.target())).norm() <= near;
        let gradient = o.field.gradient(p);
        let direction = gradient.and_then(|g| unit(&g));
        // Along a streamline the guidance turns slowly; a reversal from one step to the next
        // means the body sits on a critical point (a saddle), where the direction is undefined.
        // Only within one field: across a re-solve the two directions are two fields' (measured:
        // the 8-robot crossing, a robot whose re-solved field went round a neighbour's other
        // side, smooth along both fields, was counted lost for that one step).
        let reversed = !o.replanned
            && matches!((direction, self.last_direction), (Some(u), Some(last)) if u.dot(&last) < 0.0);
        self.last_direction = direction;
        // Only a harmonic field can be flat to working precision (in `W = 1 - V`), measured at
        // the scale of the cells around `p` (deep in a maze `W` and `∇W` are far below f64).
        let flat = o.field.harmonic().is_some_and(|h| {
            h.sampler
                .w_and_grad_scaled(p)
                .is_some_and(|(w, g)| g.norm() * cell <= FLAT_RELATIVE_CHANGE * w)
        });
        let lost = !near_target && !o.giving_way && (direction.is_none() || flat || reversed);
        if lost {
            self.faults.guidance_lost_steps += 1;
            if !self.guidance_lost {
                events.push(format!(
                    "guidance lost at ({:.3}, {:.3}): a critical point of the field, a flat region, or off the field",
                    p[0], p[1]
                ));
            }
        }
        self.guidance_lost = lost;

        let penetrating = o.signed_clearance < -PENETRATION_TOLERANCE;
        if penetrating && !self.penetrating {
            self.faults.penetrations += 1;
            events.push(format!(
                "pushed {:.3} m into a wall at ({:.3}, {:.3})",
                -o.signed_clearance, p[0], p[1]
            ));
        }
        self.penetrating = penetrating;

        let (lo, hi) = o.bounds;
        let outside = !(lo[0]..=hi[0]).contains(&p[0]) || !(lo[1]..=hi[1]).contains(&p[1]);
        if outside {
            self.faults.left_box_steps += 1;
            if !self.outside {
                events.push(format!("left the box at ({:.3}, {:.3})", p[0], p[1]));
            }
        }
        self.outside = outside;
        events
    }
}
