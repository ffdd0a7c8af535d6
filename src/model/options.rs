//! Simulation options (MJCF `<option>`, MuJoCo's `mjOption`) as typed values with MuJoCo 4.0's
//! defaults (MuJoCo documentation, "XML Reference → option").

/// Numerical integrator (`<option integrator>`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Integrator {
    /// Semi-implicit Euler (MuJoCo's default).
    #[default]
    Euler,
    /// Classical fourth-order Runge–Kutta.
    Rk4,
    /// Implicit in velocity (passive, actuator and Coriolis/centrifugal derivatives).
    Implicit,
    /// `implicit` without the Coriolis derivatives.
    ImplicitFast,
}

impl Integrator {
    /// The name MJCF uses.
    pub fn mjcf_name(self) -> &'static str {
        match self {
            Integrator::Euler => "Euler",
            Integrator::Rk4 => "RK4",
            Integrator::Implicit => "implicit",
            Integrator::ImplicitFast => "implicitfast",
        }
    }
}

/// Friction cone of the soft contact model (`<option cone>`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Cone {
    /// Each friction direction as a pair of rows on the edges of a pyramid (MuJoCo's default).
    #[default]
    Pyramidal,
    /// One row per friction direction, within an elliptic cone.
    Elliptic,
}

/// Constraint solver of the soft mode (`<option solver>`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Solver {
    /// Projected Gauss–Seidel on the dual (`PGS`).
    Pgs,
    /// Nonlinear conjugate gradient on the primal (`CG`).
    Cg,
    /// Newton's method on the primal (`Newton`, MuJoCo's default).
    #[default]
    Newton,
}

/// Constraint Jacobian storage (`<option jacobian>`); kept as written, lagrange does not read
/// it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum JacobianStorage {
    /// Dense (`dense`).
    Dense,
    /// Sparse (`sparse`).
    Sparse,
    /// Dense up to 60 degrees of freedom, sparse above (MuJoCo's rule).
    #[default]
    Auto,
}

/// `<option><flag>`: each switch with MuJoCo's default. `true` means the feature is on
/// (MuJoCo's "disable" flags default to on, its "enable" flags to off).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Flags {
    /// All constraints (`mjDSBL_CONSTRAINT`).
    pub constraint: bool,
    /// Equality constraints (`mjDSBL_EQUALITY`).
    pub equality: bool,
    /// Joint and tendon friction-loss rows (`mjDSBL_FRICTIONLOSS`).
    pub frictionloss: bool,
    /// Joint and tendon limit rows (`mjDSBL_LIMIT`).
    pub limit: bool,
    /// Contacts: collision detection and contact rows (`mjDSBL_CONTACT`).
    pub contact: bool,
    /// Passive joint springs (`mjDSBL_SPRING`; applied when the model is compiled).
    pub spring: bool,
    /// Passive damping of joints and actuators (`mjDSBL_DAMPER`).
    pub damper: bool,
    /// Gravity (`mjDSBL_GRAVITY`).
    pub gravity: bool,
    /// Clamping controls to `ctrlrange` (`mjDSBL_CLAMPCTRL`).
    pub clampctrl: bool,
    /// Warm start of the soft constraint solver (`mjDSBL_WARMSTART`).
    pub warmstart: bool,
    /// Filtering out contacts between a body and its parent (`mjDSBL_FILTERPARENT`).
    pub filterparent: bool,
    /// Actuator forces (`mjDSBL_ACTUATION`).
    pub actuation: bool,
    /// Raising `solref`'s time constant to at least twice the time step (`mjDSBL_REFSAFE`).
    pub refsafe: bool,
    /// Sensors (`mjDSBL_SENSOR`); lagrange does not read it.
    pub sensor: bool,
    /// Mid-phase collision filtering (`mjDSBL_MIDPHASE`); lagrange does not read it.
    pub midphase: bool,
    /// MuJoCo's native convex collision detection (`mjDSBL_NATIVECCD`, on by default; off,
    /// MuJoCo uses libccd's MPR); lagrange's convex pairs always follow the native solver's
    /// contact rules (see `collision::multiccd`).
    pub nativeccd: bool,
    /// Implicit joint damping in the Euler integrator (`mjDSBL_EULERDAMP`).
    pub eulerdamp: bool,
    /// Automatic reset on numerical instability (`mjDSBL_AUTORESET`); lagrange does not read it.
    pub autoreset: bool,
    /// Overriding every contact's margin, solref (also solreffriction), solimp and friction with
    /// [`Options::o_margin`], [`Options::o_solref`], [`Options::o_solimp`], [`Options::o_friction`]
    /// (`mjENBL_OVERRIDE`, MJCF `override`); the gap and condim stay the pair's.
    pub override_contacts: bool,
    /// Energy computation (`mjENBL_ENERGY`); lagrange does not read it.
    pub energy: bool,
    /// Comparing forward and inverse dynamics (`mjENBL_FWDINV`); lagrange does not read it.
    pub fwdinv: bool,
    /// Discrete-time inverse dynamics (`mjENBL_INVDISCRETE`); lagrange does not read it.
    pub invdiscrete: bool,
    /// Multi-point convex collision detection (MuJoCo 4.0's `mjDSBL_MULTICCD`, on by default):
    /// several contacts for box and mesh pairs and for capsules and cylinders against them (face,
    /// edge and segment clipping); off, one contact per convex pair (`collision::multiccd`).
    pub multiccd: bool,
    /// Constraint island discovery (`mjENBL_ISLAND`); islands are solved as one problem, listed by
    /// `info`.
    pub island: bool,
    /// Sleeping islands (`mjENBL_SLEEP`, off by default): trees at rest for `mjMINAWAKE` steps
    /// are put to sleep with their island and skipped by collision, rows and integration until
    /// woken (`forward::sleep`, docs/constraints.md "Sleeping islands"; soft mode only).
    pub sleep: bool,
}

impl Default for Flags {
    fn default() -> Self {
        Self {
            constraint: true,
            equality: true,
            frictionloss: true,
            limit: true,
            contact: true,
            spring: true,
            damper: true,
            gravity: true,
            clampctrl: true,
            warmstart: true,
            filterparent: true,
            actuation: true,
            refsafe: true,
            sensor: true,
            midphase: true,
            nativeccd: true,
            eulerdamp: true,
            autoreset: true,
            override_contacts: false,
            energy: false,
            fwdinv: false,
            invdiscrete: false,
            multiccd: true,
            island: false,
            sleep: false,
        }
    }
}

impl Flags {
    /// The switch named `name` as MJCF spells it (`override` for `override_contacts`).
    pub fn get_mut(&mut self, name: &str) -> Option<&mut bool> {
        Some(match name {
            "constraint" => &mut self.constraint,
            "equality" => &mut self.equality,
            "frictionloss" => &mut self.frictionloss,
            "limit" => &mut self.limit,
            "contact" => &mut self.contact,
            "spring" => &mut self.spring,
            "damper" => &mut self.damper,
            "gravity" => &mut self.gravity,
            "clampctrl" => &mut self.clampctrl,
            "warmstart" => &mut self.warmstart,
            "filterparent" => &mut self.filterparent,
            "actuation" => &mut self.actuation,
            "refsafe" => &mut self.refsafe,
            "sensor" => &mut self.sensor,
            "midphase" => &mut self.midphase,
            "nativeccd" => &mut self.nativeccd,
            "eulerdamp" => &mut self.eulerdamp,
            "autoreset" => &mut self.autoreset,
            "override" => &mut self.override_contacts,
            "energy" => &mut self.energy,
            "fwdinv" => &mut self.fwdinv,
            "invdiscrete" => &mut self.invdiscrete,
            "multiccd" => &mut self.multiccd,
            "island" => &mut self.island,
            "sleep" => &mut self.sleep,
            _ => return None,
        })
    }

    /// The switches that differ from MuJoCo's defaults, as (MJCF name, on).
    pub fn changed(&self) -> Vec<(&'static str, bool)> {
        const NAMES: [&str; 25] = [
            "constraint",
            "equality",
            "frictionloss",
            "limit",
            "contact",
            "spring",
            "damper",
            "gravity",
            "clampctrl",
            "warmstart",
            "filterparent",
            "actuation",
            "refsafe",
            "sensor",
            "midphase",
            "nativeccd",
            "eulerdamp",
            "autoreset",
            "override",
            "energy",
            "fwdinv",
            "invdiscrete",
            "multiccd",
            "island",
            "sleep",
        ];
        let (mut this, mut default) = (*self, Flags::default());
        NAMES
            .iter()
            .filter_map(|&n| {
                let on = *this.get_mut(n).expect("every listed name is a flag");
                (on != *default.get_mut(n).expect("every listed name is a flag")).then_some((n, on))
            })
            .collect()
    }
}

/// Simulation options (MJCF `<option>`; MuJoCo's defaults for URDF).
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Time step (s); MuJoCo's default 0.002.
    pub timestep: f64,
    /// Numerical integrator (`integrator`).
    pub integrator: Integrator,
    /// Friction cone of the soft mode (`cone`).
    pub cone: Cone,
    /// Constraint solver of the soft mode (`solver`).
    pub solver: Solver,
    /// Constraint Jacobian storage (`jacobian`; not read).
    pub jacobian: JacobianStorage,
    /// Maximum iterations of the constraint solver (100).
    pub iterations: u32,
    /// Relative improvement below which the solver stops (1e-8).
    pub tolerance: f64,
    /// Maximum line-search iterations of the Newton and CG solvers (50).
    pub ls_iterations: u32,
    /// Line-search tolerance (0.01).
    pub ls_tolerance: f64,
    /// Iterations of the no-slip post-processing solver (0: off).
    pub noslip_iterations: u32,
    /// Tolerance of the no-slip solver's scaled improvement (1e-6).
    pub noslip_tolerance: f64,
    /// Ratio of frictional to normal constraint impedance (1).
    pub impratio: f64,
    /// The medium's density (kg/m³; MuJoCo's fluid forces act when density or viscosity is
    /// positive: `dynamics::fluid`, docs/fluid.md).
    pub density: f64,
    /// The medium's viscosity (Pa·s; fluid forces, `dynamics::fluid`).
    pub viscosity: f64,
    /// The medium's velocity in the world frame (m/s; fluid forces, `dynamics::fluid`).
    pub wind: [f64; 3],
    /// The global magnetic flux in the world frame, read by magnetometer sensors (MuJoCo's
    /// `magnetic`, default (0, −0.5, 0)).
    pub magnetic: [f64; 3],
    /// Tolerance of MuJoCo's convex collision solver (`ccd_tolerance`, 1e-6), read by lagrange's
    /// copy of that solver (`collision::ccd`).
    pub ccd_tolerance: f64,
    /// Iteration limit of MuJoCo's convex collision solver (`ccd_iterations`, 35), read by
    /// lagrange's copy of that solver (`collision::ccd`).
    pub ccd_iterations: u32,
    /// The velocity (m/s, each dof's speed scaled by its `dof_length`) below which a tree may
    /// fall asleep (MuJoCo's `sleep_tolerance`, default 1e-3; read with `<flag sleep>`).
    pub sleep_tolerance: f64,
    /// The most contacts one collision pass keeps, when set: replaces the default budget of
    /// [`Model::contact_budget`](crate::Model::contact_budget) (500 with the solvers that form
    /// rows × rows matrices: the exact mode, PGS, no-slip), bounded only by memory (the rows'
    /// Jacobian and, for those solvers, one rows × rows matrix within 1 GiB). Contacts beyond it
    /// are dropped, counted and warned about as beyond the default budget. None (the default):
    /// the default budget. CLI `--max-contacts N`, [`LoadOptions::max_contacts`](crate::io::LoadOptions).
    /// (MJCF's `<size nconmax>` is a legacy attribute MuJoCo 4.0 ignores, and so does lagrange.)
    pub max_contacts: Option<usize>,
    /// The `<flag>` switches.
    pub flags: Flags,
    /// Contact margin under `<flag override>` (m; MuJoCo's `o_margin`, default 0).
    pub o_margin: f64,
    /// Contact solref under `<flag override>` (`o_solref`, default `0.02 1`).
    pub o_solref: [f64; 2],
    /// Contact solimp under `<flag override>` (`o_solimp`, default `0.9 0.95 0.001 0.5 2`).
    pub o_solimp: [f64; 5],
    /// Contact friction under `<flag override>` (`o_friction`, default `1 1 0.005 0.0001 0.0001`;
    /// each entry at least MuJoCo's `mjMINMU` = 1e-5).
    pub o_friction: [f64; 5],
}

impl Default for Options {
    fn default() -> Self {
        Self {
            timestep: 0.002,
            integrator: Integrator::Euler,
            cone: Cone::Pyramidal,
            solver: Solver::Newton,
            jacobian: JacobianStorage::Auto,
            iterations: 100,
            tolerance: 1e-8,
            ls_iterations: 50,
            ls_tolerance: 0.01,
            noslip_iterations: 0,
            noslip_tolerance: 1e-6,
            impratio: 1.0,
            density: 0.0,
            viscosity: 0.0,
            wind: [0.0; 3],
            magnetic: [0.0, -0.5, 0.0],
            ccd_tolerance: 1e-6,
            ccd_iterations: 35,
            sleep_tolerance: 1e-3,
            max_contacts: None,
            flags: Flags::default(),
            o_margin: 0.0,
            o_solref: [0.02, 1.0],
            o_solimp: [0.9, 0.95, 0.001, 0.5, 2.0],
            o_friction: [1.0, 1.0, 0.005, 0.0001, 0.0001],
        }
    }
}
