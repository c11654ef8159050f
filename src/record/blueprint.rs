//! The viewer layout stored in every recording: the world on the left (above a view that
//! follows the first agent, when the world is large or long and thin beside the agent), the
//! plots on the right, one view per quantity, on the `sim_time` timeline, opening at the end of
//! the run (the whole trail in view; scrub or press play to replay it). Without it the viewer
//! would guess a view per plot and a view rooted at the field image.
//!
//! Every plot view shows the whole run: left to itself the viewer shows a long run's plots
//! zoomed in on the last instant (a 400 s maze opened on 0.02 s of chatter). Rerun 0.36's
//! blueprint builder cannot set a view's properties (the time axis' range, a 2-D view's
//! bounds), so the builder's blueprint is captured, the properties are logged into the same
//! blueprint store beside it, and the whole is sent as one blueprint.

use rerun::blueprint::components::PlayState;
use rerun::blueprint::{
    Blueprint, BlueprintActivation, ContainerLike, Horizontal, Spatial2DView, TextDocumentView,
    TimePanel, TimeSeriesView, Vertical,
};
use rerun::datatypes::{TimeRange, TimeRangeBoundary, VisibleTimeRange};
use rerun::external::re_log_types::{BlueprintActivationCommand, LogMsg};
use rerun::external::re_sdk_types::blueprint::archetypes::{
    TimeAxis, ViewContents, VisibleTimeRanges, VisualBounds2D,
};
use rerun::external::uuid::Uuid;
use rerun::log::{Chunk, RowId};
use rerun::{
    AsComponents, RecordingStream, RecordingStreamBuilder, RecordingStreamError,
    SerializedComponentBatch,
};

use super::names::{
    AGENT_PLOTS, AGENTS, ARM_PLOTS, AgentPaths, ArmPaths, PENDULUM_PLOTS, Plot, SHAPED_PLOTS,
    SIM_TIME, SUMMARY, WORLD, plot,
};
use crate::world::World;

/// Half the width and half the height of what the follow view shows around the agent, m.
pub const FOLLOW_HALF_EXTENT: [f64; 2] = [4.0, 2.5];
/// A world this many times wider (or higher) than the follow view, or this many times longer
/// than it is wide, gets a follow view: the agent is too small to see in the whole world.
const FOLLOW_WHEN: f64 = 4.0;

/// What the SDK's builder cannot set, to be logged beside its blueprint: entities of the
/// blueprint store and their archetypes.
#[derive(Default)]
struct Settings(Vec<(String, Box<dyn AsComponents>)>);

impl Settings {
    /// Sets `view`'s property `name` (the archetype's name) to `value`.
    fn property(&mut self, view: &ContainerLike, name: &str, value: impl AsComponents + 'static) {
        if let ContainerLike::View(v) = view {
            self.0
                .push((format!("{}/{name}", v.blueprint_path()), Box::new(value)));
        }
    }

    /// Shows `entity` in `view` at every time from the start up to the time cursor, not at the
    /// cursor alone.
    fn up_to_cursor(&mut self, view: &ContainerLike, entity: &str) {
        let ContainerLike::View(v) = view else {
            return;
        };
        let id = v
            .blueprint_path()
            .last()
            .and_then(|part| Uuid::parse_str(part.unescaped_str()).ok())
            .expect("a view's blueprint path ends with its id");
        let path = ViewContents::blueprint_base_visualizer_path_for_entity(id, &entity.into());
        let range = VisibleTimeRange {
            timeline: SIM_TIME.into(),
            range: TimeRange {
                start: TimeRangeBoundary::Infinite,
                end: TimeRangeBoundary::AT_CURSOR,
            },
        };
        self.0
            .push((path.to_string(), Box::new(VisibleTimeRanges::new([range]))));
    }
}

/// The layout's messages for `world`, being made on a thread of their own (the SDK's builder
/// starts recording streams to make them, which takes about a millisecond): start it first,
/// [`send`] it when the recording is set up.
pub struct Prepared(std::thread::JoinHandle<Result<Layout, RecordingStreamError>>);

/// A blueprint store's messages and the command that activates it.
pub struct Layout {
    messages: Vec<LogMsg>,
    activate: BlueprintActivationCommand,
}

/// Starts making the layout for `world`.
pub fn prepare(world: &World) -> Prepared {
    let (blueprint, Settings(settings)) = layout(world);
    // Serialized here: the archetypes need not be sent across threads.
    let properties: Vec<(String, Vec<SerializedComponentBatch>)> = settings
        .into_iter()
        .map(|(path, value)| (path, value.as_serialized_batches()))
        .collect();
    Prepared(std::thread::spawn(move || {
        messages(&blueprint, &properties)
    }))
}

/// Sends the layout on `rec`, to every sink it has.
pub fn send(rec: &RecordingStream, layout: Prepared) -> Result<(), RecordingStreamError> {
    let Layout { messages, activate } = layout
        .0
        .join()
        .unwrap_or_else(|panic| std::panic::resume_unwind(panic))?;
    rec.send_blueprint(messages, activate);
    Ok(())
}

/// The messages of `blueprint` with `properties` (entity path, archetype) in the same store.
fn messages(
    blueprint: &Blueprint,
    properties: &[(String, Vec<SerializedComponentBatch>)],
) -> Result<Layout, RecordingStreamError> {
    // The builder's messages, captured: a blueprint store, and the command that activates it.
    let (capture, storage) = RecordingStreamBuilder::new("nadf").memory()?;
    blueprint.send(&capture, BlueprintActivation::default())?;
    let mut messages = storage.take();
    let activate = messages
        .iter()
        .find_map(|m| match m {
            LogMsg::BlueprintActivationCommand(c) => Some(c.clone()),
            _ => None,
        })
        .expect("a blueprint is sent with the command that activates it");
    let store = activate.blueprint_id.clone();
    messages
        .retain(|m| m.store_id() == &store && !matches!(m, LogMsg::BlueprintActivationCommand(_)));
    // The properties, into the same store, on the builder's `blueprint` timeline (as chunks
    // made here: a stream of their own would cost another thread and flush).
    let when = rerun::TimePoint::default().with(rerun::Timeline::new_sequence("blueprint"), 0);
    for (path, batches) in properties {
        let chunk = Chunk::builder(path.as_str())
            .with_serialized_batches(RowId::new(), when.clone(), batches.iter().cloned())
            .build()?;
        messages.push(LogMsg::ArrowMsg(store.clone(), chunk.to_arrow_msg()?));
    }
    Ok(Layout { messages, activate })
}

/// The layout for `world`, and what the builder cannot set. Every agent's field image is
/// logged, but only the first agent's is shown (they overlap); the others can be switched on
/// in the viewer. The plot views are those of the plot tables (`names.rs`) that some body has,
/// in their order.
fn layout(world: &World) -> (Blueprint, Settings) {
    let mut settings = Settings::default();
    let mut spatial = vec![format!("+ /{WORLD}/**"), format!("+ /{AGENTS}/**")];
    for agent in world.agents.iter().skip(1) {
        spatial.push(format!("- {}", AgentPaths::field_of(&agent.name)));
    }
    let mut spatial_views: Vec<ContainerLike> = vec![
        Spatial2DView::new(world.name())
            .with_origin("/")
            .with_contents(spatial.clone())
            .into(),
    ];
    let mut world_share = 1.0;
    if let Some((follow, bounds, share)) = follow_view(world, spatial) {
        let follow = follow.into();
        settings.property(&follow, "VisualBounds2D", bounds);
        spatial_views.push(follow);
        world_share = share;
    }
    // The trails are logged a segment at a time: each view shows them up to the cursor.
    for view in &spatial_views {
        for agent in world.agents.iter().chain(&world.shaped) {
            settings.up_to_cursor(view, &format!("/{}", AgentPaths::of(&agent.name).trail));
        }
        for arm in &world.arms {
            settings.up_to_cursor(view, &format!("/{}", ArmPaths::of(&arm.name).trail));
        }
    }
    // An arm's joint space, with its field and its path, beside the world: both joints of two
    // links; the last two of three, in the slice through the first joint's angle.
    let joint_views: Vec<ContainerLike> = (world.arms.iter())
        .map(|a| {
            let origin = format!("/{}", ArmPaths::of(&a.name).joint_space);
            let title = if a.links.len() == 2 {
                format!("{}: joint space (q₁ →, q₂ ↓)", a.name)
            } else {
                format!("{}: joint space at the current q₁ (q₂ →, q₃ ↓)", a.name)
            };
            let view: ContainerLike = Spatial2DView::new(title)
                .with_origin(origin.clone())
                .with_contents([format!("+ {origin}/**")])
                .into();
            settings.up_to_cursor(&view, &format!("{origin}/path"));
            view
        })
        .collect();
    let mut left: ContainerLike = if spatial_views.len() == 1 {
        spatial_views.remove(0)
    } else {
        Vertical::new(spatial_views)
            .with_row_shares([world_share, 1.0 - world_share])
            .into()
    };
    if !joint_views.is_empty() {
        let n = joint_views.len() as f32;
        let mut column = vec![left];
        column.extend(joint_views);
        let mut shares = vec![1.0];
        shares.extend(std::iter::repeat_n(0.8 / n, column.len() - 1));
        left = Vertical::new(column).with_row_shares(shares).into();
    }
    let mut views = plot_views(AGENT_PLOTS, &world.agents, |a| a.name.as_str());
    views.extend(plot_views(SHAPED_PLOTS, &world.shaped, |a| a.name.as_str()));
    views.extend(plot_views(ARM_PLOTS, &world.arms, |a| a.name.as_str()));
    views.extend(plot_views(PENDULUM_PLOTS, &world.pendulums, |p| {
        p.name.as_str()
    }));
    let mut right: Vec<ContainerLike> = views
        .into_iter()
        .map(|v| {
            let v = v.into();
            // The whole run, whatever its length.
            let axis = TimeAxis::new().with_view_range(TimeRange::EVERYTHING);
            settings.property(&v, "TimeAxis", axis);
            v
        })
        .collect();
    right.push(
        TextDocumentView::new("summary")
            .with_origin(format!("/{SUMMARY}"))
            .into(),
    );
    let blueprint = Blueprint::new(
        Horizontal::new([left, Vertical::new(right).into()]).with_column_shares([3.0, 2.0]),
    )
    .with_auto_views(false)
    .with_time_panel(
        TimePanel::new()
            .with_timeline(SIM_TIME)
            .with_play_state(PlayState::Following),
    );
    (blueprint, settings)
}

/// A view rooted at the first agent's body (which moves with it and is turned y-down, so the
/// view follows the agent with the world upright), showing [`FOLLOW_HALF_EXTENT`] around it;
/// its bounds; and the share of the left column the whole world keeps above it. None for a
/// world small and square enough to show the agent whole.
fn follow_view(
    world: &World,
    contents: Vec<String>,
) -> Option<(Spatial2DView, VisualBounds2D, f32)> {
    let agent = world.agents.first()?;
    let [w, h] = world.size;
    let [hx, hy] = FOLLOW_HALF_EXTENT;
    let (long, short) = (w.max(h), w.min(h).max(f64::MIN_POSITIVE));
    let large = w >= FOLLOW_WHEN * 2.0 * hx || h >= FOLLOW_WHEN * 2.0 * hy;
    if !large && long / short < FOLLOW_WHEN {
        return None;
    }
    let view = Spatial2DView::new(format!("following {}", agent.name))
        .with_origin(format!("/{}", AgentPaths::of(&agent.name).body))
        .with_contents(contents);
    let bounds = VisualBounds2D::new(rerun::datatypes::Range2D {
        x_range: [-hx, hx].into(),
        y_range: [-hy, hy].into(),
    });
    // A world much wider than high needs little height to be seen whole.
    let world_share = ((h / w) as f32).clamp(0.2, 0.6);
    Some((view, bounds, world_share))
}

/// One time-series view per plot of `table`, with that plot of every owner that has some of
/// its series (`/plots/OWNER/KEY`); none for a plot no owner has a series of.
fn plot_views<Owner, State>(
    table: &[Plot<Owner, State>],
    owners: &[Owner],
    name: impl Fn(&Owner) -> &str,
) -> Vec<TimeSeriesView> {
    table
        .iter()
        .filter_map(|p| {
            let contents: Vec<String> = owners
                .iter()
                .filter(|o| p.series_of(o).next().is_some())
                .map(|o| format!("+ /{}", plot(name(o), p.key)))
                .collect();
            (!contents.is_empty()).then(|| TimeSeriesView::new(p.view).with_contents(contents))
        })
        .collect()
}
