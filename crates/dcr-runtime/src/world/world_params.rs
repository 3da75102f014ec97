//! [`WorldParams`] and [`ClassifyParams`]: the settings of a [`crate::DcrWorld`].

/// How the world tells impacts from resting contacts (see [`crate::DcrWorld`], "Impacts and
/// resting contacts"). All counts are rigid-body steps of the world (including those passed
/// with [`crate::DcrWorld::advance`]). The defaults suit engines that create contacts before
/// they carry an impulse (rapier's predictive contacts) and report every step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClassifyParams {
    /// Ages rule: a contact can be an impact while its age (steps since it appeared, or last
    /// had zero impulse) is at most this, and it has not been an impact on that object since.
    /// Default 2: a contact with zero impulse at step k fires when its impulse arrives at
    /// k + 1 or k + 2.
    pub fresh_steps: u64,
    /// The contacts of the first `settle_steps` steps (the initial resting set, e.g. objects
    /// placed on a table, settling under gravity) are never impacts. Default 3.
    pub settle_steps: u64,
    /// Ages rule: a contact id absent from the reports for at least this many consecutive
    /// steps is a new contact when it comes back: its age restarts, so it can be an impact
    /// again (a bouncing body). Default 1.
    pub new_after_missing_steps: u64,
    /// `true`: the engine's newness rule instead of ages — an impact is a report with
    /// [`crate::ContactReport::is_new`], impulse > 0 and ≥ the object's threshold, after the
    /// settle window; no age table is kept. For callers that report contacts only on some
    /// steps (passing the others with [`crate::DcrWorld::advance`]), where ages cannot see
    /// what happened in between. Default `false` (ages).
    pub engine_newness: bool,
    /// Smallest approach speed of an impact (m/s, ≥ 0): the normal speed at which the two
    /// bodies closed at the point before its impulse, `k λ − u⁺` (k: the pair's inverse
    /// effective mass along the normal from the reported [`crate::BodyState`]s, λ the point's
    /// impulse, u⁺ its separation speed after the step). A fresh contact that closed slower is
    /// resting, under either rule. For engines that re-create the points of a sliding or
    /// rolling contact (Bullet's persistent manifolds): the new points carry a resting weight,
    /// which closes at about g·h over a step, and are no impacts; 2 g h leaves them out and
    /// keeps a fall of more than 2 g h² (2 mm at h = 10 ms). Per point: an impact spread over
    /// n points reads about 1/n of its speed at each. Default 0 (no minimum).
    pub min_approach_speed: f64,
}

impl Default for ClassifyParams {
    fn default() -> Self {
        ClassifyParams {
            fresh_steps: 2,
            settle_steps: 3,
            new_after_missing_steps: 1,
            engine_newness: false,
            min_approach_speed: 0.0,
        }
    }
}

/// Settings of a [`crate::DcrWorld`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldParams {
    /// Rigid-body time step h (s), the same every step; every object's response uses it.
    /// Default 0.01.
    pub h: f64,
    /// Impact / resting classification. Default [`ClassifyParams::default`].
    pub classify: ClassifyParams,
    /// Energy bound η ∈ [0, 1]: per elastic object and step, the kinetic energy its responses
    /// give the receiving bodies is at most η × the energy the step's impacts on the object
    /// dissipated (plus what chained impulses gave its body); the object's impulses are scaled
    /// uniformly when they would exceed it. `None`: no bound. Default `Some(1.0)`: passive (a
    /// response never adds more energy than its impacts lost), which leaves responses below
    /// the bound untouched — in the paper's six scenes it never binds (docs/benchmarks.md).
    pub energy_eta: Option<f64>,
    /// Longest chain of responses through dynamic elastic objects in one step (an impulse on an
    /// elastic object's body becomes an impact on it): 0 disables chains. Default 4.
    pub max_chain_depth: u32,
    /// Gravity (m/s², world frame) for the support compensation: a body a response lifts off
    /// along n (Δv ≥ g_n h, `g_n = max(0, −g·n)`) also gets `g_n h` of normal velocity at its
    /// centre of mass, as its own event (`delta_v` 0) — the support its contact would have
    /// given it over the step in which it leaves. So it ends its first step off the contact
    /// with the response's Δv, gravity included: the separation velocity the response asks for
    /// is the engine body's velocity once it is off (without it the body ends that step at Δv −
    /// g_n h and flies g_n h² lower from then on: 0.98 mm at h = 10 ms). A smaller push gets
    /// none and leaves the body on its contact, so µm/s responses do not make bodies hop and
    /// land as new impacts. `[0, 0, 0]`: no compensation. `dcr-rapier` sets it from rapier's
    /// gravity in both application modes: in the solver the replay's restitution pass sends
    /// the body off at the end of the replay step, and gravity acts over the next one just the
    /// same.
    ///
    /// Default: **unset** (NaN), which [`crate::DcrWorld::new`] refuses: only the engine knows
    /// its gravity, and a world left without it would lose g·h of every lifting push without a
    /// word (0.098 m/s at h = 10 ms: in the Bullet dinner example the plates rose 28–56 % as
    /// high). Set it to the engine's gravity ([`WorldParams::with_gravity`]), or to zero for no
    /// compensation.
    pub gravity: [f64; 3],
}

impl WorldParams {
    /// The default parameters with the engine's `gravity` (m/s², world frame; `[0, 0, 0]` for
    /// no support compensation).
    pub fn with_gravity(gravity: [f64; 3]) -> WorldParams {
        WorldParams {
            gravity,
            ..WorldParams::default()
        }
    }

    /// Whether [`WorldParams::gravity`] was left unset (any component NaN).
    pub fn gravity_unset(&self) -> bool {
        self.gravity.iter().any(|g| g.is_nan())
    }
}

impl Default for WorldParams {
    fn default() -> Self {
        WorldParams {
            h: 0.01,
            classify: ClassifyParams::default(),
            energy_eta: Some(1.0),
            max_chain_depth: 4,
            gravity: [f64::NAN; 3],
        }
    }
}
