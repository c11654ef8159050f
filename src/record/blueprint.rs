//! The viewer layout stored in every recording: the world on the left, the time series on the
//! right, grouped by quantity, on the `sim_time` timeline, opening at the end of the run (the
//! whole trail in view; scrub or press play to replay it). Without it the viewer would guess a
//! view per plot and a view rooted at the field image.

use rerun::blueprint::components::PlayState;
use rerun::blueprint::{Blueprint, Horizontal, Spatial2DView, TimePanel, TimeSeriesView, Vertical};

use crate::world::World;

/// The layout for `world`. Every agent's field image is logged, but only the first agent's is
/// shown (they overlap); the others can be switched on in the viewer.
pub fn layout(world: &World) -> Blueprint {
    let mut spatial = vec!["+ /world/**".to_string(), "+ /agents/**".to_string()];
    for agent in world.agents.iter().skip(1) {
        spatial.push(format!("- /agents/{}/field/**", agent.name));
    }
    let agents: Vec<&str> = world.agents.iter().map(|a| a.name.as_str()).collect();
    let series = |title: &str, names: &[&str]| series_view(title, &agents, names);
    let mut views = vec![
        series("distance to target (m)", &["distance"]).into(),
        series("speed (m/s)", &["speed", "radial_speed"]).into(),
        series("control force (N)", &["force", "force_x", "force_y"]).into(),
        series("potential V", &["potential"]).into(),
    ];
    // The clamping, speed-limit and bias signals, when some agent has them.
    if world
        .agents
        .iter()
        .any(|a| a.controller.clamp.is_some() || a.controller.speed_limit.is_some())
    {
        views.push(series("limits active (0/1)", &["clamping", "speed_limited"]).into());
    }
    if world.agents.iter().any(|a| a.controller.bias.is_some()) {
        views.push(series("bias β (N)", &["beta_x", "beta_y"]).into());
    }
    if !world.pendulums.is_empty() {
        let pendulums: Vec<&str> = world.pendulums.iter().map(|p| p.name.as_str()).collect();
        let pendulum_series = |title: &str, names: &[&str]| series_view(title, &pendulums, names);
        if world.agents.is_empty() {
            views.clear();
        }
        views.push(pendulum_series("pendulum angle θ (rad)", &["theta", "target"]).into());
        views.push(pendulum_series("torque u (N·m)", &["torque"]).into());
        views.push(pendulum_series("bias β (N·m)", &["beta"]).into());
    }
    Blueprint::new(
        Horizontal::new([
            Spatial2DView::new(world.name())
                .with_origin("/")
                .with_contents(spatial)
                .into(),
            Vertical::new(views).into(),
        ])
        .with_column_shares([3.0, 2.0]),
    )
    .with_auto_views(false)
    .with_time_panel(
        TimePanel::new()
            .with_timeline("sim_time")
            .with_play_state(PlayState::Following),
    )
}

/// A time-series view of the series `names` of every body in `owners` (`/plots/OWNER/NAME`).
fn series_view(title: &str, owners: &[&str], names: &[&str]) -> TimeSeriesView {
    let contents: Vec<String> = owners
        .iter()
        .flat_map(|o| names.iter().map(move |n| format!("+ /plots/{o}/{n}")))
        .collect();
    TimeSeriesView::new(title).with_contents(contents)
}
