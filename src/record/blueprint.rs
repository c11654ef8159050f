//! The viewer layout stored in every recording: the world on the left, the time series on the
//! right, grouped by quantity, on the `sim_time` timeline, opening at the end of the run (the
//! whole trail in view; scrub or press play to replay it). Without it the viewer would guess a
//! view per plot and a view rooted at the field image.

use rerun::blueprint::components::PlayState;
use rerun::blueprint::{
    Blueprint, ContainerLike, Horizontal, Spatial2DView, TextDocumentView, TimePanel,
    TimeSeriesView, Vertical,
};

use super::names::{
    AGENT_SERIES, AGENTS, AgentPaths, PENDULUM_SERIES, SUMMARY, Series, WORLD, plot,
};
use crate::world::World;

/// The layout for `world`. Every agent's field image is logged, but only the first agent's is
/// shown (they overlap); the others can be switched on in the viewer. The time-series views
/// are those of the series table (`names.rs`) that some body has, in its order.
pub fn layout(world: &World) -> Blueprint {
    let mut spatial = vec![format!("+ /{WORLD}/**"), format!("+ /{AGENTS}/**")];
    for agent in world.agents.iter().skip(1) {
        spatial.push(format!("- {}", AgentPaths::field_of(&agent.name)));
    }
    let mut views = series_views(AGENT_SERIES, &world.agents, |a| a.name.as_str());
    views.extend(series_views(PENDULUM_SERIES, &world.pendulums, |p| {
        p.name.as_str()
    }));
    views.push(
        TextDocumentView::new("summary")
            .with_origin(format!("/{SUMMARY}"))
            .into(),
    );
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

/// One time-series view per view title of `table`, in order, with the series of every owner
/// that has them (`/plots/OWNER/KEY`); none for a title no owner has a series of.
fn series_views<Owner, State>(
    table: &[Series<Owner, State>],
    owners: &[Owner],
    name: impl Fn(&Owner) -> &str,
) -> Vec<ContainerLike> {
    let mut titles: Vec<&str> = table.iter().map(|s| s.view).collect();
    titles.dedup();
    titles
        .into_iter()
        .filter_map(|title| {
            let contents: Vec<String> = owners
                .iter()
                .flat_map(|o| {
                    table
                        .iter()
                        .filter(move |s| s.view == title && (s.shown)(o))
                        .map(|s| format!("+ /{}", plot(name(o), s.key)))
                })
                .collect();
            (!contents.is_empty())
                .then(|| TimeSeriesView::new(title).with_contents(contents).into())
        })
        .collect()
}
