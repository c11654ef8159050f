//! Semantic checks that serde cannot express: positive sizes, finite numbers, convex polygons,
//! agents that start in free space. Each problem is a dotted key path and a message; the loader
//! turns the path into a line of the file.

use super::body::BodyShape;
use super::schema::{
    Agent, AgentShape, Attraction, ControllerKind, ControllerSettings, Expect, FieldKind,
    FieldSettings, GuidanceKind, Integration, MAX_CELLS, SensorKind, SensorSettings, Wall, World,
};
use super::shapes::{named_walls, wall_shape};

/// Every problem in a parsed world, as `(key path, message)`; empty when the world is valid.
pub fn validate(world: &World) -> Vec<(String, String)> {
    let mut issues = Vec::new();
    let mut bad = |key: String, message: String| issues.push((key, message));

    positive(&mut bad, "size.0", world.size[0]);
    positive(&mut bad, "size.1", world.size[1]);
    positive(&mut bad, "dt", world.dt);
    positive(&mut bad, "duration", world.duration);
    if let Some(at) = world.distance_at {
        non_negative(&mut bad, "distance_at", at);
    }
    positive(&mut bad, "field.cell", world.field.cell);
    non_negative(
        &mut bad,
        "field.obstacle_horizon",
        world.field.obstacle_horizon,
    );
    finite_point(
        &mut bad,
        "external_acceleration",
        world.external_acceleration,
    );
    finite_point(&mut bad, "origin", world.origin);
    if let Some(map) = &world.map
        && let Some(cell) = map.cell
    {
        positive(&mut bad, "map.cell", cell);
    }
    if !(world.field.tolerance > 0.0 && world.field.tolerance < 1.0) {
        bad(
            "field.tolerance".into(),
            format!("must be in (0, 1), got {}", world.field.tolerance),
        );
    }
    if world.size.iter().all(|s| s.is_finite() && *s > 0.0)
        && world.field.cell.is_finite()
        && world.field.cell > 0.0
    {
        let cells = ((world.size[0] / world.field.cell).ceil() + 1.0)
            * ((world.size[1] / world.field.cell).ceil() + 1.0);
        let limit = world.field.max_cells;
        if cells > limit as f64 {
            bad(
                "field.cell".into(),
                format!(
                    "a {} m cell over a {} × {} m box makes {cells:.0} grid cells, more than field.max_cells = {limit} (default {MAX_CELLS} = 4096²); use a larger cell, or raise field.max_cells (about 40 bytes per cell and agent)",
                    world.field.cell, world.size[0], world.size[1]
                ),
            );
        }
    }
    check_field_kind(&mut bad, &world.field);
    non_negative(&mut bad, "field.replan_hz", world.field.replan_hz);
    non_negative(&mut bad, "field.replan_reach", world.field.replan_reach);
    let window = world.field.replan_window;
    if !(window.is_finite() && window >= 3.0 * world.field.cell) {
        bad(
            "field.replan_window".into(),
            format!(
                "must be at least three cells ({} m), got {window}",
                3.0 * world.field.cell
            ),
        );
    }
    if world.dt.is_finite() && world.duration.is_finite() && world.dt > world.duration {
        bad(
            "dt".into(),
            format!(
                "the step ({} s) is longer than the duration ({} s)",
                world.dt, world.duration
            ),
        );
    }

    for (i, wall) in world.walls.iter().enumerate() {
        check_wall(&mut bad, &format!("walls.{i}"), wall);
    }
    for i in 0..world.obstacles.len() {
        super::obstacle::check(&mut bad, world, i);
    }

    if let Some(expect) = &world.expect {
        // A world with a shaped agent has it alone (see `check_shaped`): its summary's metrics.
        if world.agents.iter().any(Agent::is_shaped) {
            check_shaped_expect(&mut bad, "expect", expect);
        } else {
            check_expect(&mut bad, "expect", expect);
        }
    }
    for (i, agent) in world.agents.iter().enumerate() {
        if let Some(expect) = &agent.expect {
            let key = format!("agents.{i}.expect");
            if agent.is_shaped() {
                check_shaped_expect(&mut bad, &key, expect);
            } else {
                check_expect(&mut bad, &key, expect);
            }
        }
    }

    for (i, arm) in world.arms.iter().enumerate() {
        check_arm(&mut bad, world, i, arm);
    }
    if world.agents.is_empty()
        && world.shaped.is_empty()
        && world.pendulums.is_empty()
        && world.arms.is_empty()
    {
        bad(
            "agents".into(),
            "a world needs at least one [[agents]], [[pendulums]] or [[arms]] entry".into(),
        );
    }
    for (i, p) in world.pendulums.iter().enumerate() {
        let key = |name: &str| format!("pendulums.{i}.{name}");
        finite_point(&mut bad, &key("pivot"), p.pivot);
        positive(&mut bad, &key("length"), p.length);
        positive(&mut bad, &key("mass"), p.mass);
        for (name, x) in [("start", p.start), ("target", p.target)] {
            if !x.is_finite() {
                bad(key(name), format!("must be a finite angle, got {x}"));
            }
        }
        non_negative(&mut bad, &key("controller.k"), p.controller.k);
        non_negative(&mut bad, &key("controller.b"), p.controller.b);
        if let Some(bias) = &p.controller.bias {
            positive(&mut bad, &key("controller.bias.alpha"), bias.alpha);
            non_negative(&mut bad, &key("controller.bias.dwell"), bias.dwell);
        }
        if world.agents.iter().any(|a| a.name == p.name)
            || world.pendulums[..i].iter().any(|q| q.name == p.name)
        {
            bad(key("name"), format!("`{}` is used twice", p.name));
        }
    }
    for (i, agent) in world.agents.iter().enumerate() {
        check_agent(&mut bad, world, i, agent);
    }
    if world.agents.iter().any(Agent::is_shaped) {
        check_headings(&mut bad, world);
    }
    issues
}

/// An arm: two or three links of positive length, mass and radius; limits with min < max and
/// even cells; a start inside them and clear of the walls; exactly one target, within reach.
fn check_arm(
    bad: &mut impl FnMut(String, String),
    world: &World,
    i: usize,
    arm: &crate::world::ArmSettings,
) {
    let key = |k: &str| format!("arms.{i}.{k}");
    let n = arm.links.len();
    if !(2..=3).contains(&n) {
        let hint = if n == 1 {
            " (a single link on a joint is a [[pendulums]] entry)"
        } else {
            ""
        };
        bad(
            key("links"),
            format!("an arm has two or three [[arms.links]], got {n}{hint}"),
        );
        return;
    }
    if world
        .agents
        .iter()
        .chain(&world.shaped)
        .any(|a| a.name == arm.name)
        || world.pendulums.iter().any(|p| p.name == arm.name)
        || world.arms[..i].iter().any(|a| a.name == arm.name)
    {
        bad(key("name"), format!("`{}` is used twice", arm.name));
    }
    finite_point(bad, &key("base"), arm.base);
    let mut ok = true;
    for (l, link) in arm.links.iter().enumerate() {
        let at = |k: &str| key(&format!("links.{l}.{k}"));
        for (name, x) in [
            ("length", link.length),
            ("mass", link.mass),
            ("radius", link.radius),
        ] {
            if !(x.is_finite() && x > 0.0) {
                bad(
                    at(name),
                    format!("must be a positive finite number, got {x}"),
                );
                ok = false;
            }
        }
        if let Some(c) = link.com
            && !(c.is_finite() && (0.0..=link.length).contains(&c))
        {
            bad(
                at("com"),
                format!(
                    "must be between 0 and the link's length ({}), got {c}",
                    link.length
                ),
            );
            ok = false;
        }
        if let Some([lo, hi]) = link.limits
            && !(lo.is_finite() && hi.is_finite() && lo < hi)
        {
            bad(
                at("limits"),
                format!("must be [min, max] with min < max, got [{lo}, {hi}]"),
            );
            ok = false;
        }
    }
    let cells = arm.cells.unwrap_or(arm.cells() as i64);
    if cells < 8 || cells % 2 != 0 {
        bad(
            key("cells"),
            format!("must be an even whole number of at least 8, got {cells}"),
        );
        ok = false;
    } else if (cells as f64).powi(n as i32) > world.field.max_cells as f64 {
        bad(
            key("cells"),
            format!(
                "{cells} cells per joint make {} joint-space cells, more than field.max_cells = {}",
                (cells as f64).powi(n as i32),
                world.field.max_cells
            ),
        );
        ok = false;
    }
    for (name, q) in [
        ("start", Some(&arm.start)),
        ("target_joints", arm.target_joints.as_ref()),
    ] {
        let Some(q) = q else { continue };
        if q.len() != n {
            bad(
                key(name),
                format!("expected {n} joint angles (one per link), got {}", q.len()),
            );
            ok = false;
            continue;
        }
        for (l, (angle, link)) in q.iter().zip(&arm.links).enumerate() {
            if !angle.is_finite() {
                bad(
                    key(name),
                    format!("joint {l}: must be a finite angle, got {angle}"),
                );
                ok = false;
            } else if let Some([lo, hi]) = link.limits
                && !(lo..=hi).contains(angle)
            {
                bad(
                    key(name),
                    format!("joint {l}: {angle} rad is outside its limits [{lo}, {hi}]"),
                );
                ok = false;
            }
        }
    }
    match (&arm.target_joints, arm.target_point) {
        (Some(_), Some(_)) | (None, None) => {
            bad(
                key("target_joints"),
                "give exactly one of target_joints (rad) and target_point (m)".into(),
            );
            ok = false;
        }
        (None, Some(p)) if ok => {
            let reach: f64 = arm.links.iter().map(|l| l.length).sum();
            let d = (p[0] - arm.base[0]).hypot(p[1] - arm.base[1]);
            if !(p[0].is_finite() && p[1].is_finite()) || d > reach + arm.target_radius {
                bad(
                    key("target_point"),
                    format!(
                        "[{}, {}] is {d:.3} m from the base, out of the arm's reach ({reach} m)",
                        p[0], p[1]
                    ),
                );
                ok = false;
            }
        }
        _ => {}
    }
    if !(arm.target_radius.is_finite() && arm.target_radius > 0.0) {
        bad(
            key("target_radius"),
            format!(
                "must be a positive finite number, got {}",
                arm.target_radius
            ),
        );
        ok = false;
    }
    check_controller(bad, &|k| key(&format!("controller.{k}")), &arm.controller);
    if let Some(e) = &arm.expect
        && let Err(problems) = crate::expect::bounds_of::<crate::sim::arm_run::ArmSummary>(e)
    {
        for (name, message) in problems {
            bad(key(&format!("expect.{name}")), message);
        }
    }
    guidance_and_damping_only(bad, &key("controller.kind"), arm.controller.kind, "an arm");
    if !ok {
        return;
    }
    // The start clear of the walls and of itself (links not jointed to each other).
    let chain = arm.chain();
    let joints = chain.joints(&arm.start);
    let segments: Vec<[[f64; 2]; 2]> = joints.windows(2).map(|w| [w[0], w[1]]).collect();
    for (l, s) in segments.iter().enumerate() {
        let r = chain.links[l].radius;
        let hit = named_walls(world).find(|(_, wall)| {
            wall_shape(wall).is_some_and(|w| {
                let segment = parry2d::shape::Segment::new(
                    parry2d::math::Vector::new(s[0][0], s[0][1]),
                    parry2d::math::Vector::new(s[1][0], s[1][1]),
                );
                parry2d::query::distance(
                    &parry2d::math::Pose::IDENTITY,
                    &segment,
                    &w.pose,
                    w.shape.as_ref(),
                )
                .is_ok_and(|d| d.distance <= r)
            })
        });
        if let Some((wall, _)) = hit {
            bad(
                key("start"),
                format!("link {l} overlaps or touches {wall} at the start"),
            );
            return;
        }
        for (k, t) in segments.iter().enumerate().take(l.saturating_sub(1)) {
            if crate::field::segment_distance(*s, *t) <= r + chain.links[k].radius {
                bad(
                    key("start"),
                    format!("links {k} and {l} overlap at the start"),
                );
                return;
            }
        }
    }
}

/// The laws a body other than a disc takes so far: guidance with NADF or viscous damping (the
/// sliding mode and ORCA are the plane's); `body` says which, in the message.
fn guidance_and_damping_only(
    bad: &mut impl FnMut(String, String),
    key: &str,
    kind: ControllerKind,
    body: &str,
) {
    if !matches!(kind, ControllerKind::Nadf | ControllerKind::Viscous) {
        bad(
            key.to_string(),
            format!(
                "`{}` is not available for {body}: use `nadf` or `viscous`",
                kind.name()
            ),
        );
    }
}

/// `field.headings` for a shaped agent: even (the solver's periodic red-black colouring), at
/// least 8 (a slice's interval below 45°), and the (x, y, θ) grid within `field.max_cells`.
fn check_headings(bad: &mut impl FnMut(String, String), world: &World) {
    let n = world.field.headings;
    if n < 8 || n % 2 != 0 {
        bad(
            "field.headings".into(),
            format!(
                "must be an even whole number of at least 8 (heading cells over a turn), got {n}"
            ),
        );
        return;
    }
    if world.size.iter().all(|s| s.is_finite() && *s > 0.0)
        && world.field.cell.is_finite()
        && world.field.cell > 0.0
    {
        let plane = ((world.size[0] / world.field.cell).ceil() + 1.0)
            * ((world.size[1] / world.field.cell).ceil() + 1.0);
        let cells = plane * n as f64;
        let limit = world.field.max_cells;
        if cells > limit as f64 {
            bad(
                "field.headings".into(),
                format!(
                    "{n} headings of {plane:.0} cells make {cells:.0} (x, y, θ) cells, more than field.max_cells = {limit}; use fewer headings or a larger field.cell, or raise field.max_cells"
                ),
            );
        }
    }
}

/// Settings that are valid but will not work as intended, as `(key path, message)`:
/// condition 40 of Proposition 3 (`condition_40`) and gains faster than the time step
/// (`unresolved_gains`).
pub fn warnings(world: &World) -> Vec<(String, String)> {
    let mut out = condition_40(world);
    out.extend(unresolved_gains(world));
    out
}

/// Gains whose time scale is shorter than the step: a damping with `B dt/m > 2` or a stiffness
/// with `K dt²/m > 4` (`ω dt > 2`), the limits beyond which an explicit step diverges. The
/// control laws' linear parts are integrated exactly (`control::Integrator`), so such a run
/// is stable and its rest points are right, but what happens within one damping time or one
/// period is not resolved: the warning gives the step that would resolve it.
pub fn unresolved_gains(world: &World) -> Vec<(String, String)> {
    let dt = world.dt;
    let mut out = Vec::new();
    let mut check = |key: String, what: &str, x: f64, bound: f64, resolving: f64, exact: bool| {
        if x > bound && exact {
            out.push((
                key,
                format!(
                    "{what} is faster than the step: {x:.3} > {bound} (an explicit step would diverge). The law is integrated exactly, so the run is stable and its rest points are right, but the motion within one step is not resolved; dt ≤ {resolving:.3e} s resolves it"
                ),
            ));
        } else if x > bound {
            out.push((
                key,
                format!(
                    "{what} is faster than the step: {x:.3} > {bound}, and with integration = \"explicit\" the run will diverge; use dt ≤ {resolving:.3e} s or the default integration"
                ),
            ));
        }
    };
    // One body of mass (or moment of inertia) `m`: its damping and its stiffness.
    let mut body = |prefix: &str,
                    unit: &str,
                    m: f64,
                    damping: Option<(&str, f64)>,
                    stiffness: Option<(&str, f64)>,
                    exact: bool| {
        if let Some((name, b)) = damping {
            let what = format!("the damping (B·dt/{unit})");
            check(
                format!("{prefix}.{name}"),
                &what,
                b * dt / m,
                2.0,
                2.0 * m / b,
                exact,
            );
        }
        if let Some((name, k)) = stiffness {
            let what = format!("the stiffness (K·dt²/{unit})");
            let resolving = 2.0 * (m / k).sqrt();
            check(
                format!("{prefix}.{name}"),
                &what,
                k * dt * dt / m,
                4.0,
                resolving,
                exact,
            );
        }
    };
    for (i, agent) in world.agents.iter().enumerate() {
        let c = &agent.controller;
        let damped = matches!(c.kind, ControllerKind::Nadf | ControllerKind::Viscous);
        body(
            &format!("agents.{i}.controller"),
            "m",
            agent.mass,
            c.b.filter(|_| damped).map(|b| ("b", b)),
            c.clamp.map(|clamp| ("clamp.kc", clamp.kc)),
            c.integration == Integration::Exact,
        );
    }
    for (i, p) in world.pendulums.iter().enumerate() {
        let c = &p.controller;
        body(
            &format!("pendulums.{i}.controller"),
            "(M L²)",
            p.mass * p.length * p.length,
            Some(("b", c.b)),
            Some(("k", c.k)),
            true,
        );
    }
    out
}

/// Condition 40 of Proposition 3: the guidance must beat the external force outside the
/// clamping region, or the body may never reach the target.
///
/// With normalized guidance the thrust outside σ is at least `K·min(1, σ/r_c)` (σ is the clamp's
/// radius, or `r_c` without a clamp), and the external force along the guidance is at most
/// `m·|a|`; the warning fires when the first does not exceed the second. Gradient guidance
/// needs the solved field to check, so it is not checked here. Sliding mode needs `F_0 > m·|a|`.
pub fn condition_40(world: &World) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let [ax, ay] = world.external_acceleration;
    let a = ax.hypot(ay);
    if !(a.is_finite() && a > 0.0) {
        return out;
    }
    for (i, agent) in world.agents.iter().enumerate() {
        let c = &agent.controller;
        let external = agent.mass * a;
        match c.kind {
            ControllerKind::Nadf | ControllerKind::Viscous => {
                if world.field.guidance != GuidanceKind::Normalized {
                    continue;
                }
                let sigma = c.clamp.map_or(c.capture_radius, |clamp| clamp.sigma);
                let taper = if c.capture_radius > 0.0 {
                    (sigma / c.capture_radius).min(1.0)
                } else {
                    1.0
                };
                let thrust = c.k() * taper;
                if thrust <= external {
                    out.push((
                        format!("agents.{i}.controller.k"),
                        format!(
                            "condition 40 may fail: outside {sigma} m of the target the guidance pushes with as little as K·min(1, σ/r_c) = {thrust:.3} N, not more than the external force m·|a| = {external:.3} N; the body may stall or drift away before reaching the target (raise k above {:.3} N, or the clamp's sigma)",
                            external / taper
                        ),
                    ));
                }
            }
            // ORCA and the unicycle track a velocity; they have no guidance force to compare.
            ControllerKind::Orca | ControllerKind::Unicycle => {}
            ControllerKind::SlidingMode => {
                let f0 = c.f0.unwrap_or(0.0);
                if f0 <= external {
                    out.push((
                        format!("agents.{i}.controller.f0"),
                        format!(
                            "F_0 = {f0} N does not exceed the external force m·|a| = {external:.3} N: the sliding mode cannot reach its surface"
                        ),
                    ));
                }
            }
        }
    }
    out
}

/// A lidar's own keys: required and in range for a lidar, absent for the walls sensor.
fn check_lidar(
    bad: &mut impl FnMut(String, String),
    key: &dyn Fn(&str) -> String,
    world: &World,
    sensor: &SensorSettings,
) {
    let given = [
        ("range", sensor.range.is_some()),
        ("rays", sensor.rays.is_some()),
        ("fov", sensor.fov.is_some()),
        ("dropout", sensor.dropout.is_some()),
    ];
    if sensor.kind == SensorKind::Walls {
        for (name, is) in given {
            if is {
                bad(
                    key(name),
                    format!("only a lidar has `{name}` (set kind = \"lidar\")"),
                );
            }
        }
        return;
    }
    if world.field.kind != FieldKind::Harmonic {
        bad(
            key("kind"),
            "a lidar builds a map for the harmonic field; the attractive-repulsive field is not supported".into(),
        );
    }
    if sensor.position_noise != 0.0 {
        bad(
            key("position_noise"),
            "a lidar's noise is on its ranges (`noise`); position noise is for the walls sensor"
                .into(),
        );
    }
    match sensor.range {
        None => bad(key("range"), "a lidar needs `range` (m)".into()),
        Some(r) => positive(bad, &key("range"), r),
    }
    if sensor.rays == Some(0) {
        bad(key("rays"), "must be at least 1, got 0".into());
    }
    if let Some(fov) = sensor.fov
        && !(fov > 0.0 && fov <= 360.0)
    {
        bad(
            key("fov"),
            format!("must be in (0, 360] degrees, got {fov}"),
        );
    }
    if let Some(p) = sensor.dropout
        && !(0.0..1.0).contains(&p)
    {
        bad(
            key("dropout"),
            format!("must be a probability in [0, 1), got {p}"),
        );
    }
}

fn positive(bad: &mut impl FnMut(String, String), key: &str, x: f64) {
    if !(x.is_finite() && x > 0.0) {
        bad(
            key.into(),
            format!("must be a positive finite number, got {x}"),
        );
    }
}

fn non_negative(bad: &mut impl FnMut(String, String), key: &str, x: f64) {
    if !(x.is_finite() && x >= 0.0) {
        bad(key.into(), format!("must be a finite number ≥ 0, got {x}"));
    }
}

/// The parameters each kind of controller needs, and no others.
fn check_controller(
    bad: &mut impl FnMut(String, String),
    key: &dyn Fn(&str) -> String,
    c: &ControllerSettings,
) {
    let kind = c.kind.name();
    let needs =
        |bad: &mut dyn FnMut(String, String), name: &str, value: Option<f64>, what: &str| {
            if value.is_none() {
                bad(
                    key(name),
                    format!("kind = \"{kind}\" needs `{name}` ({what})"),
                );
            }
        };
    let unused = |bad: &mut dyn FnMut(String, String), name: &str, value: Option<f64>| {
        if value.is_some() {
            bad(key(name), format!("is not used by kind = \"{kind}\""));
        }
    };
    match c.kind {
        ControllerKind::Nadf | ControllerKind::Viscous => {
            needs(&mut *bad, "b", c.b, "the damping coefficient, N·s/m");
            unused(&mut *bad, "vd", c.vd);
            unused(&mut *bad, "f0", c.f0);
        }
        ControllerKind::SlidingMode => {
            needs(&mut *bad, "vd", c.vd, "the desired speed, m/s");
            needs(&mut *bad, "f0", c.f0, "the control magnitude, N");
            unused(&mut *bad, "k", c.k);
            unused(&mut *bad, "b", c.b);
        }
        ControllerKind::Orca => {
            needs(
                &mut *bad,
                "speed_limit",
                c.speed_limit,
                "ORCA's top speed, m/s",
            );
            unused(&mut *bad, "k", c.k);
            unused(&mut *bad, "b", c.b);
            unused(&mut *bad, "vd", c.vd);
            unused(&mut *bad, "f0", c.f0);
        }
        ControllerKind::Unicycle => {
            unused(&mut *bad, "k", c.k);
            unused(&mut *bad, "b", c.b);
            unused(&mut *bad, "vd", c.vd);
            unused(&mut *bad, "f0", c.f0);
        }
    }
    if c.kind != ControllerKind::Unicycle && c.turn_gain.is_some() {
        bad(
            key("turn_gain"),
            format!("is not used by kind = \"{kind}\""),
        );
    }
    if let Some(k) = c.turn_gain {
        positive(bad, &key("turn_gain"), k);
    }
    if let Some(b) = c.envelope_damping {
        positive(bad, &key("envelope_damping"), b);
        if !c.envelope {
            bad(
                key("envelope_damping"),
                "is not used with envelope = false".into(),
            );
        }
    }
    if c.kind == ControllerKind::Unicycle && c.envelope_damping.is_some() {
        bad(
            key("envelope_damping"),
            "is not used by kind = \"unicycle\" (its wheels limit it)".into(),
        );
    }
    if c.kind != ControllerKind::Orca && c.orca.is_some() {
        bad(key("orca"), format!("is not used by kind = \"{kind}\""));
    }
    if let Some(o) = &c.orca {
        positive(bad, &key("orca.time_horizon"), o.time_horizon);
        positive(bad, &key("orca.neighbour_distance"), o.neighbour_distance);
        positive(bad, &key("orca.tracking_time"), o.tracking_time);
    }
    if let Some(k) = c.k {
        positive(bad, &key("k"), k);
    }
    if let Some(b) = c.b {
        non_negative(bad, &key("b"), b);
    }
    for (name, value) in [
        ("vd", c.vd),
        ("f0", c.f0),
        ("speed_limit", c.speed_limit),
        ("brake", c.brake),
        ("max_force", c.max_force),
    ] {
        if let Some(x) = value {
            positive(bad, &key(name), x);
        }
    }
    non_negative(bad, &key("capture_radius"), c.capture_radius);
    if let Some(clamp) = &c.clamp {
        positive(bad, &key("clamp.kc"), clamp.kc);
        positive(bad, &key("clamp.sigma"), clamp.sigma);
    }
    if let Some(bias) = &c.bias {
        positive(bad, &key("bias.alpha"), bias.alpha);
        non_negative(bad, &key("bias.dwell"), bias.dwell);
    }
}

/// The attractive-repulsive keys: required with that kind, rejected without it (a stray `eta`
/// in a harmonic world would otherwise be silently ignored).
fn check_field_kind(bad: &mut impl FnMut(String, String), field: &FieldSettings) {
    let keys = [("field.eta", field.eta), ("field.rho0", field.rho0)];
    match field.kind {
        FieldKind::AttractiveRepulsive => {
            for (key, value) in keys {
                match value {
                    Some(x) => positive(bad, key, x),
                    None => bad(
                        key.into(),
                        "is required with field.kind = \"attractive-repulsive\"".into(),
                    ),
                }
            }
        }
        FieldKind::Harmonic => {
            for (key, value) in keys {
                if value.is_some() {
                    bad(
                        key.into(),
                        "is only used with field.kind = \"attractive-repulsive\"".into(),
                    );
                }
            }
            if field.attraction != Attraction::default() {
                bad(
                    "field.attraction".into(),
                    "is only used with field.kind = \"attractive-repulsive\"".into(),
                );
            }
        }
    }
}

fn check_expect(bad: &mut impl FnMut(String, String), key: &str, e: &Expect) {
    if let Err(problems) = crate::expect::bounds(e) {
        for (name, message) in problems {
            bad(format!("{key}.{name}"), message);
        }
    }
}

/// [`check_expect`] for a shaped agent, whose summary has the heading's metrics too.
fn check_shaped_expect(bad: &mut impl FnMut(String, String), key: &str, e: &Expect) {
    if let Err(problems) = crate::expect::bounds_of::<crate::sim::shaped::ShapedSummary>(e) {
        for (name, message) in problems {
            bad(format!("{key}.{name}"), message);
        }
    }
}

fn finite_point(bad: &mut impl FnMut(String, String), key: &str, p: [f64; 2]) -> bool {
    let ok = p.iter().all(|c| c.is_finite());
    if !ok {
        bad(
            key.into(),
            format!("must be finite, got [{}, {}]", p[0], p[1]),
        );
    }
    ok
}

pub(super) fn check_wall(bad: &mut impl FnMut(String, String), key: &str, wall: &Wall) {
    match wall {
        Wall::Box {
            center,
            half_extents,
            angle,
        } => {
            finite_point(bad, &format!("{key}.center"), *center);
            positive(bad, &format!("{key}.half_extents.0"), half_extents[0]);
            positive(bad, &format!("{key}.half_extents.1"), half_extents[1]);
            if !angle.is_finite() {
                bad(
                    format!("{key}.angle"),
                    format!("must be finite, got {angle}"),
                );
            }
        }
        Wall::Segment { a, b, thickness } => {
            let ok = finite_point(bad, &format!("{key}.a"), *a)
                & finite_point(bad, &format!("{key}.b"), *b);
            positive(bad, &format!("{key}.thickness"), *thickness);
            if ok && a == b {
                bad(
                    format!("{key}.b"),
                    "a segment needs two distinct end points".into(),
                );
            }
        }
        Wall::Disc { center, radius } => {
            finite_point(bad, &format!("{key}.center"), *center);
            positive(bad, &format!("{key}.radius"), *radius);
        }
        Wall::Polygon { points } => {
            let key = format!("{key}.points");
            if points.len() < 3 {
                bad(
                    key,
                    format!("a polygon needs at least 3 points, got {}", points.len()),
                );
                return;
            }
            if !points
                .iter()
                .enumerate()
                .all(|(j, p)| finite_point(bad, &format!("{key}.{j}"), *p))
            {
                return;
            }
            let n = points.len();
            let turns_left = (0..n).all(|j| {
                let [a, b, c] = [points[j], points[(j + 1) % n], points[(j + 2) % n]];
                (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]) > 0.0
            });
            if !turns_left {
                bad(
                    key,
                    "must be convex with its points in counter-clockwise order and no three in a line".into(),
                );
            } else if wall_shape(wall).is_none() {
                bad(
                    key,
                    "parry cannot build a convex polygon from these points".into(),
                );
            }
        }
    }
}

fn check_agent(bad: &mut impl FnMut(String, String), world: &World, i: usize, agent: &Agent) {
    let key = |k: &str| format!("agents.{i}.{k}");
    if agent.name.is_empty()
        || !agent
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    {
        bad(
            key("name"),
            format!(
                "`{}` must be non-empty and use only letters, digits, `-` and `_` (it becomes an entity path)",
                agent.name
            ),
        );
    }
    if let Some(j) = world.agents[..i].iter().position(|a| a.name == agent.name) {
        bad(
            key("name"),
            format!("`{}` is already the name of agents.{j}", agent.name),
        );
    }
    positive(bad, &key("radius"), agent.radius);
    positive(bad, &key("mass"), agent.mass);
    check_controller(bad, &|k| key(&format!("controller.{k}")), &agent.controller);
    if let Some(sensor) = &agent.sensor {
        check_lidar(bad, &|k| key(&format!("sensor.{k}")), world, sensor);
        non_negative(bad, &key("sensor.noise"), sensor.noise);
        non_negative(bad, &key("sensor.position_noise"), sensor.position_noise);
        positive(bad, &key("sensor.rate"), sensor.rate);
        if sensor.rate.is_finite()
            && world.dt.is_finite()
            && world.dt > 0.0
            && sensor.rate * world.dt > 1.0 + 1e-9
        {
            bad(
                key("sensor.rate"),
                format!(
                    "{} Hz is faster than the physics step ({} Hz): at most one reading per step",
                    sensor.rate,
                    1.0 / world.dt
                ),
            );
        }
    }
    finite_point(bad, &key("initial_velocity"), agent.initial_velocity);
    let start_ok = finite_point(bad, &key("start"), agent.start);
    let target_ok = finite_point(bad, &key("target"), agent.target);
    if agent.is_shaped() {
        if agent.drive.is_some() {
            bad(
                key("drive"),
                "wheels are for a disc so far: a shape other than a disc is pushed and turned by forces ([agents.shape]); drop one of the two".into(),
            );
        }
        check_shaped(bad, world, i, agent, start_ok && target_ok);
        return;
    }
    if let Some(drive) = &agent.drive {
        check_drive(bad, i, agent, drive);
    } else if agent.controller.kind == ControllerKind::Unicycle {
        bad(
            key("controller.kind"),
            "unicycle steers a robot on wheels: give the agent an [agents.drive]".into(),
        );
    }
    let turns = agent.drive.is_some();
    for (name, set) in [
        ("heading", agent.heading != 0.0 && !turns),
        ("target_heading", agent.target_heading.is_some()),
        ("inertia", agent.inertia.is_some() && !turns),
    ] {
        if set {
            bad(
                key(name),
                "only for an agent with a shape other than a disc ([agents.shape]) or with wheels ([agents.drive]): a disc without them does not turn".into(),
            );
        }
    }
    if !(agent.radius.is_finite() && agent.radius > 0.0) {
        return;
    }
    let (lo, hi) = world.bounds();
    for (what, p, ok) in [
        ("start", agent.start, start_ok),
        ("target", agent.target, target_ok),
    ] {
        if !ok {
            continue;
        }
        let r = agent.radius;
        if p[0] < lo[0] + r || p[1] < lo[1] + r || p[0] > hi[0] - r || p[1] > hi[1] - r {
            bad(
                key(what),
                format!(
                    "[{}, {}] puts the disc (radius {r} m) outside the box [{}, {}] × [{}, {}]",
                    p[0], p[1], lo[0], hi[0], lo[1], hi[1]
                ),
            );
            continue;
        }
        if let Some(wall) = blocking_wall(world, p, r) {
            bad(
                key(what),
                format!(
                    "[{}, {}] is inside or touching {wall} (the disc has radius {r} m)",
                    p[0], p[1]
                ),
            );
        }
    }
    if let Some(r_t) = agent.target_radius {
        if !(r_t.is_finite() && r_t > 0.0) {
            bad(
                key("target_radius"),
                format!("must be a positive finite number, got {r_t}"),
            );
        } else if start_ok && target_ok {
            let d = (agent.start[0] - agent.target[0]).hypot(agent.start[1] - agent.target[1]);
            if d <= r_t {
                bad(
                    key("target_radius"),
                    format!(
                        "{r_t} m reaches the start, {d:.3} m from the target: the agent would start on its target"
                    ),
                );
            } else if let Some(wall) = blocking_wall(world, agent.target, agent.radius + r_t) {
                bad(
                    key("target_radius"),
                    format!(
                        "the target disc of {r_t} m reaches where the agent's centre cannot be: within its radius ({} m) of {wall}; make it smaller",
                        agent.radius
                    ),
                );
            }
        }
    }
    if start_ok {
        for (j, other) in world.agents[..i].iter().enumerate() {
            let d = (agent.start[0] - other.start[0]).hypot(agent.start[1] - other.start[1]);
            if d < agent.radius + other.radius {
                bad(
                    key("start"),
                    format!(
                        "overlaps the start of agents.{j} (`{}`): centres {d:.3} m apart",
                        other.name
                    ),
                );
            }
        }
    }
}

/// The checks of an agent's wheels: positive separation, speed and force (and grip), a
/// look-ahead inside the footprint (the controlled point must be ahead of the axle to be
/// actuated, and on the body), a finite heading and inertia, and a law that acts on a point.
fn check_drive(
    bad: &mut impl FnMut(String, String),
    i: usize,
    agent: &Agent,
    drive: &crate::world::DriveSettings,
) {
    let key = |k: &str| format!("agents.{i}.{k}");
    for (name, value) in [
        ("wheel_separation", Some(drive.wheel_separation)),
        ("max_wheel_speed", Some(drive.max_wheel_speed)),
        ("max_wheel_force", Some(drive.max_wheel_force)),
        ("lateral_grip", drive.lateral_grip),
    ] {
        if let Some(v) = value
            && !(v.is_finite() && v > 0.0)
        {
            bad(
                key(&format!("drive.{name}")),
                format!("must be a positive finite number, got {v}"),
            );
        }
    }
    if let Some(l) = drive.lookahead {
        if !(l.is_finite() && l > 0.0) {
            bad(
                key("drive.lookahead"),
                format!(
                    "must be a positive finite distance ahead of the axle, got {l}: on the axle the point cannot be moved sideways (it is not actuated)"
                ),
            );
        } else if agent.radius.is_finite() && l > agent.radius {
            bad(
                key("drive.lookahead"),
                format!(
                    "{l} m is beyond the body (radius {} m): the controlled point must be on the robot",
                    agent.radius
                ),
            );
        }
    }
    if !agent.heading.is_finite() {
        bad(
            key("heading"),
            format!("must be a finite angle, got {}", agent.heading),
        );
    }
    if let Some(inertia) = agent.inertia
        && !(inertia.is_finite() && inertia > 0.0)
    {
        bad(
            key("inertia"),
            format!("must be a positive finite number, got {inertia}"),
        );
    }
    if agent.controller.kind == ControllerKind::SlidingMode {
        bad(
            key("controller.kind"),
            "sliding-mode is not supported with wheels: use nadf, viscous, orca or unicycle".into(),
        );
    }
    if agent.initial_velocity != [0.0, 0.0] {
        bad(
            key("initial_velocity"),
            "a robot on wheels starts at rest (a sideways velocity would break its grip)".into(),
        );
    }
}

/// The checks of an agent with a shape planned in (x, y, θ): a valid shape, finite headings,
/// what shaped agents support so far, and a start and a target pose clear of every wall.
fn check_shaped(
    bad: &mut impl FnMut(String, String),
    world: &World,
    i: usize,
    agent: &Agent,
    points_ok: bool,
) {
    let key = |k: &str| format!("agents.{i}.{k}");
    let shape = agent.shape.as_ref().expect("a shaped agent");
    let shape_key = match shape {
        AgentShape::Box { .. } => key("shape.half_extents"),
        AgentShape::Polygon { .. } => key("shape.points"),
        _ => key("shape.parts"),
    };
    if let AgentShape::Box { half_extents } = shape
        && !half_extents.iter().all(|h| h.is_finite() && *h > 0.0)
    {
        bad(
            shape_key.clone(),
            format!(
                "must be two positive finite numbers, got [{}, {}]",
                half_extents[0], half_extents[1]
            ),
        );
        return;
    }
    if (shape.parts().iter().flatten()).any(|p| !p.iter().all(|c| c.is_finite())) {
        bad(shape_key, "every point must be finite".into());
        return;
    }
    let body = match BodyShape::of(shape) {
        Ok(body) => body.expect("not a disc"),
        Err(e) => {
            bad(shape_key, e.to_string());
            return;
        }
    };
    let mut ok = points_ok;
    if !agent.heading.is_finite() {
        bad(
            key("heading"),
            format!("must be a finite angle, got {}", agent.heading),
        );
        ok = false;
    }
    if let Some(t) = agent.target_heading
        && !t.is_finite()
    {
        bad(
            key("target_heading"),
            format!("must be a finite angle, got {t}"),
        );
        ok = false;
    }
    if let Some(inertia) = agent.inertia {
        positive(bad, &key("inertia"), inertia);
    }
    guidance_and_damping_only(
        bad,
        &key("controller.kind"),
        agent.controller.kind,
        "a shaped agent yet",
    );
    if agent.sensor.is_some() {
        bad(
            key("sensor"),
            "a shaped agent knows the walls exactly: sensors are not available for it yet".into(),
        );
    }
    if world.field.kind != FieldKind::Harmonic {
        bad(
            "field.kind".into(),
            "a shaped agent is guided by the harmonic field in (x, y, θ): use `harmonic`".into(),
        );
    }
    if world.agents.len() > 1 {
        bad(
            key("shape"),
            format!(
                "a shaped agent must be the world's only agent for now (it has {}): other agents are not yet planned around a shape",
                world.agents.len()
            ),
        );
    }
    if let Some(r_t) = agent.target_radius
        && !(r_t.is_finite() && r_t > 0.0)
    {
        bad(
            key("target_radius"),
            format!("must be a positive finite number, got {r_t}"),
        );
    }
    if !ok {
        return;
    }
    // The start at its heading; the target at its heading, or without one at any heading of
    // a fine set (the field needs a free pose there, whichever).
    let any: Vec<f64> = (0..64)
        .map(|k| k as f64 * std::f64::consts::TAU / 64.0)
        .collect();
    let checks = [
        ("start", agent.start, vec![agent.heading]),
        (
            "target",
            agent.target,
            agent.target_heading.map_or(any, |t| vec![t]),
        ),
    ];
    for (what, p, headings) in checks {
        let problem = |theta: f64| pose_problem(world, &body, [p[0], p[1], theta]);
        let problems: Vec<String> = headings
            .iter()
            .map(|&t| problem(t))
            .collect::<Option<_>>()
            .unwrap_or_default();
        if problems.is_empty() {
            continue;
        }
        let message = if headings.len() == 1 {
            format!(
                "[{}, {}] at heading {} rad: {}",
                p[0], p[1], headings[0], problems[0]
            )
        } else {
            format!(
                "[{}, {}]: the shape fits at no heading there (at heading 0: {}); move the target or give a target_heading",
                p[0], p[1], problems[0]
            )
        };
        bad(key(what), message);
    }
}

/// Why `body` cannot be at `pose` (a vertex outside the box, or a wall it overlaps or
/// touches), or `None` when it can.
fn pose_problem(world: &World, body: &BodyShape, pose: [f64; 3]) -> Option<String> {
    let (lo, hi) = world.bounds();
    if let Some(v) = (body.placed(pose).iter().flatten())
        .find(|v| v[0] < lo[0] || v[1] < lo[1] || v[0] > hi[0] || v[1] > hi[1])
    {
        return Some(format!(
            "the shape's vertex [{:.3}, {:.3}] is outside the box [{}, {}] × [{}, {}]",
            v[0], v[1], lo[0], hi[0], lo[1], hi[1]
        ));
    }
    overlapping_wall(world, body, pose).map(|wall| format!("the shape overlaps or touches {wall}"))
}

/// The first wall (described for a message) that `body` at the pose `(x, y, θ)` overlaps or
/// touches, by parry.
pub fn overlapping_wall(
    world: &World,
    body: &BodyShape,
    [x, y, theta]: [f64; 3],
) -> Option<String> {
    use parry2d::math::{Pose, Vector};
    let at = Pose::new(Vector::new(x, y), theta);
    let polygons = body.polygons();
    named_walls(world)
        .find(|(_, wall)| {
            wall_shape(wall).is_some_and(|w| {
                polygons.iter().any(|p| {
                    parry2d::query::distance(&at, p, &w.pose, w.shape.as_ref())
                        .is_ok_and(|d| d.distance <= 0.0)
                })
            })
        })
        .map(|(name, _)| name)
}

/// The first wall (described for a message) that a disc of radius `r` at `p` overlaps.
fn blocking_wall(world: &World, p: [f64; 2], r: f64) -> Option<String> {
    named_walls(world)
        .find(|(_, wall)| wall_shape(wall).is_some_and(|s| s.distance_to_point(p[0], p[1]) < r))
        .map(|(name, _)| name)
}
