//! Contact laws of two spheres: the Burgoyne–Daraio loading law (paper Eq. 1) with Johnson–Cook
//! rate hardening (Eqs. 2–3) and Thornton unloading (docs/physics.md §3), and plain Hertz.
//!
//! Sign convention (docs/physics.md): approach δ and contact force F are positive in compression.

use std::cell::Cell;
use std::f64::consts::PI;

thread_local! {
    /// Law evaluations on this thread so far: (trials, commits) ([`law_evaluations`]).
    static EVALUATIONS: Cell<(u64, u64)> = const { Cell::new((0, 0)) };
}

/// Evaluations of every contact law on this thread since it started: (trials, commits). A trial
/// ([`Contact::trial`], [`Contact::trial_force`]) is one evaluation of an implicit solve; a
/// commit ([`Contact::evaluate`]) is one a step per contact, so trials over commits is the
/// solves' cost per contact-step (validation/perf/solver.md). Two thread-local counts, so the
/// counting costs a few instructions of an evaluation's hundreds.
pub fn law_evaluations() -> (u64, u64) {
    EVALUATIONS.with(Cell::get)
}

/// Counts one trial (`commit` false) or committed (`commit` true) evaluation.
#[inline]
fn count_evaluation(commit: bool) {
    EVALUATIONS.with(|c| {
        let (t, k) = c.get();
        c.set(if commit { (t, k + 1) } else { (t + 1, k) });
    });
}

/// The constant 1.6 of the yield onset, from maximising J2 below a Hertz contact (paper Sec. II).
pub const YIELD_ONSET_FACTOR: f64 = 1.6;
/// Effective radius of two 6.35 mm spheres, m, to which the paper's fits of δp and c2 refer (Eq. 1 fits).
pub const FIT_REFERENCE_RADIUS_M: f64 = 0.00159;

/// Hertz force of two elastic spheres, `F = (4/3) E* √r δ^{3/2}` (paper Eq. 1, region I).
pub fn hertz_force(e_star_pa: f64, radius_m: f64, delta_m: f64) -> f64 {
    if delta_m <= 0.0 {
        return 0.0;
    }
    4.0 / 3.0 * e_star_pa * radius_m.sqrt() * delta_m * delta_m.sqrt()
}

/// Elastic energy stored in a Hertz contact, `U = (8/15) E* √r δ^{5/2}` (integral of region I).
pub fn hertz_energy(e_star_pa: f64, radius_m: f64, delta_m: f64) -> f64 {
    if delta_m <= 0.0 {
        return 0.0;
    }
    8.0 / 15.0 * e_star_pa * radius_m.sqrt() * delta_m.powf(2.5)
}

/// The paper's fitted parameters δp, c1, c2 at q = E*/σy, scaled to radius r (paper Eq. 1 fits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittedParameters {
    /// Approach at which region III begins, m.
    pub delta_p_m: f64,
    /// Ratio of mean contact pressure to yield stress in region III, p0 = c1 σy.
    pub c1: f64,
    /// Plastic correction of the contact area, a² = 2rδ + c2, m².
    pub c2_m2: f64,
}

impl FittedParameters {
    /// Evaluates the fits at `q = E*/σy` for effective radius `radius_m` (docs/physics.md §1).
    pub fn at(q: f64, radius_m: f64) -> FittedParameters {
        let scale = radius_m / FIT_REFERENCE_RADIUS_M;
        FittedParameters {
            delta_p_m: (0.00428 / q + 1.47e-5) * scale,
            c1: -6.76 * q.powf(-0.137) + 6.304,
            c2_m2: (-3.99e-6 / q + 1.01e-9) * scale * scale,
        }
    }
}

/// Which branch of Eq. 1 a point of the loading curve lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Region {
    /// Region I, elastic Hertz.
    Hertz,
    /// Region II, mixed elastic–plastic, F = δ(α + β ln δ).
    Mixed,
    /// Region III, fully plastic, F = p0 π (2rδ + c2).
    Plastic,
}

/// The form of region II (δy < δ ≤ δp) of the loading law.
///
/// With α, β fixed by F(δy) = Fy and F(δp) = Fp (docs/physics.md §1), the published law has a slope
/// jump of 13–17 % at δy, and region II starts *above* the Hertz curve. Together with Thornton
/// unloading (and with rate hardening, which moves δy) that lets a contact return more energy
/// than it received in impacts just past yield (restitution above 1). `Smooth` adds the term
/// γ(δ − δy)(δp − δ), which vanishes at both ends (so δy, Fy, δp, Fp, α, β are the paper's) and whose
/// γ makes dF/dδ continuous at δy, as docs/physics.md §1 requires.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Region2Form {
    /// F = δ(α + β ln δ) + γ(δ − δy)(δp − δ), C¹ at δy (default).
    #[default]
    Smooth,
    /// F = δ(α + β ln δ) exactly as printed in the paper (slope jump at δy).
    Published,
}

/// How region I joins region III when region II does not exist (δp ≤ δy, docs/physics.md §1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Degenerate {
    /// Region II exists (δy < δp): the normal three-region law.
    No,
    /// δp ≤ δy: Hertz up to the crossing with the region-III line at this approach (m), then the line.
    HertzToPlasticAt(f64),
    /// δp ≤ δy and the region-III line never crosses Hertz (or p0 ≤ 0): the contact stays Hertzian.
    HertzOnly,
}

/// The quasi-static loading curve of Eq. 1 evaluated for one yield stress (static or σy*).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadingCurve {
    /// Effective modulus E*, Pa.
    pub e_star_pa: f64,
    /// Effective radius r, m.
    pub radius_m: f64,
    /// Yield stress used (σy or the dynamic σy*), Pa.
    pub yield_stress_pa: f64,
    /// Approach at first yield δy = (1/4)(r/E*²)(1.6πσy)², m.
    pub delta_y_m: f64,
    /// Force at first yield Fy = (1/6)(r/E*)²(1.6πσy)³, N.
    pub force_y_n: f64,
    /// Fitted parameters δp, c1, c2 at this σy.
    pub fit: FittedParameters,
    /// Mean plastic pressure p0 = c1 σy, Pa.
    pub p0_pa: f64,
    /// Force at the start of region III, Fp = p0 π (2 r δp + c2), N.
    pub force_p_n: f64,
    /// Region II coefficient α, N/m.
    pub alpha: f64,
    /// Region II coefficient β, N/m.
    pub beta: f64,
    /// Region II smoothing coefficient γ, N/m² (0 for the published form).
    pub gamma: f64,
    /// Whether region II is missing and how the law copes.
    pub degenerate: Degenerate,
}

impl LoadingCurve {
    /// Builds Eq. 1 for effective modulus, radius and yield stress with the C¹ region II (docs/physics.md §1).
    pub fn new(e_star_pa: f64, radius_m: f64, yield_stress_pa: f64) -> LoadingCurve {
        LoadingCurve::with_form(e_star_pa, radius_m, yield_stress_pa, Region2Form::Smooth)
    }

    /// Builds Eq. 1 with the chosen form of region II.
    pub fn with_form(
        e_star_pa: f64,
        radius_m: f64,
        yield_stress_pa: f64,
        form: Region2Form,
    ) -> LoadingCurve {
        LoadingCurve::with_form_parts(e_star_pa, radius_m, yield_stress_pa).with_region2(form)
    }

    /// The parts of Eq. 1 every approach needs (δy, Fy, the fits, p0, Fp), region II not yet set
    /// up ([`LoadingCurve::with_region2`]).
    fn with_form_parts(e_star_pa: f64, radius_m: f64, yield_stress_pa: f64) -> LoadingCurve {
        let k = YIELD_ONSET_FACTOR * PI * yield_stress_pa;
        let delta_y_m = 0.25 * radius_m / (e_star_pa * e_star_pa) * k * k;
        let force_y_n = (1.0 / 6.0) * (radius_m / e_star_pa).powi(2) * k * k * k;
        let q = e_star_pa / yield_stress_pa;
        let fit = FittedParameters::at(q, radius_m);
        let p0_pa = fit.c1 * yield_stress_pa;
        let force_p_n = p0_pa * PI * (2.0 * radius_m * fit.delta_p_m + fit.c2_m2);
        LoadingCurve {
            e_star_pa,
            radius_m,
            yield_stress_pa,
            delta_y_m,
            force_y_n,
            fit,
            p0_pa,
            force_p_n,
            alpha: 0.0,
            beta: 0.0,
            gamma: 0.0,
            degenerate: Degenerate::No,
        }
    }

    /// Whether region II exists (δy < δp with Fp > 0), so the curve is the normal three-region law.
    fn has_region2(&self) -> bool {
        self.fit.delta_p_m > self.delta_y_m && self.force_p_n > 0.0
    }

    /// Completes a curve whose δy, Fy, fit, p0 and Fp are set: region II's α, β (and γ for the
    /// smooth form), or how region I joins region III when there is no region II.
    fn with_region2(mut self, form: Region2Form) -> LoadingCurve {
        let (dy, dp) = (self.delta_y_m, self.fit.delta_p_m);
        let (force_y_n, force_p_n) = (self.force_y_n, self.force_p_n);
        if self.has_region2() {
            let beta = (dy * force_p_n - dp * force_y_n) / (dy * dp * (dp / dy).ln());
            self.beta = beta;
            self.alpha = force_y_n / dy - beta * dy.ln();
            if form == Region2Form::Smooth {
                let jump = self.alpha + beta * (dy.ln() + 1.0) - 1.5 * force_y_n / dy;
                self.gamma = -jump / (dp - dy);
            }
        } else {
            self.degenerate = self.hertz_plastic_crossing();
        }
        self
    }

    /// [`LoadingCurve::with_form`]`(…).force(delta_m)`, the same number, without computing what
    /// `delta_m` does not need: in region I or III of a three-region curve, region II's
    /// coefficients (two logarithms) are left out. What the implicit contact solves call at every
    /// trial rate (issue 20: the DEM rebuilt the whole curve at each call).
    pub fn force_for(
        e_star_pa: f64,
        radius_m: f64,
        yield_stress_pa: f64,
        form: Region2Form,
        delta_m: f64,
    ) -> f64 {
        if delta_m <= 0.0 {
            return 0.0;
        }
        // Region II only if needed: start from the curve with no region II set up yet.
        let head = LoadingCurve::with_form_parts(e_star_pa, radius_m, yield_stress_pa);
        if head.has_region2() {
            if delta_m <= head.delta_y_m {
                return hertz_force(e_star_pa, radius_m, delta_m);
            }
            if delta_m > head.fit.delta_p_m {
                return head.plastic_line(delta_m);
            }
        }
        head.with_region2(form).force(delta_m)
    }

    /// The crossing where Hertz overtakes the region-III line, used when δp ≤ δy (docs/physics.md §1).
    fn hertz_plastic_crossing(&self) -> Degenerate {
        if self.p0_pa <= 0.0 {
            return Degenerate::HertzOnly;
        }
        // f(s) = K s³ − a s² − b with s = √δ; Hertz minus line.
        let kh = 4.0 / 3.0 * self.e_star_pa * self.radius_m.sqrt();
        let a = self.p0_pa * PI * 2.0 * self.radius_m;
        let b = self.p0_pa * PI * self.fit.c2_m2;
        let f = |s: f64| kh * s * s * s - a * s * s - b;
        // f is decreasing then increasing in δ; its minimum is at √δ = 2a/(3K).
        let s_min = 2.0 * a / (3.0 * kh);
        if f(s_min) >= 0.0 {
            return Degenerate::HertzOnly;
        }
        let mut hi = s_min.max(1e-12) * 2.0;
        while f(hi) < 0.0 {
            hi *= 2.0;
        }
        let (_, hi) = crate::numeric::bisect(s_min, hi, 200, |_, _| false, |s| f(s) < 0.0);
        Degenerate::HertzToPlasticAt(hi * hi)
    }

    /// Which region of Eq. 1 the approach `delta_m` falls in.
    pub fn region(&self, delta_m: f64) -> Region {
        match self.degenerate {
            Degenerate::No => {
                if delta_m <= self.delta_y_m {
                    Region::Hertz
                } else if delta_m <= self.fit.delta_p_m {
                    Region::Mixed
                } else {
                    Region::Plastic
                }
            }
            Degenerate::HertzToPlasticAt(dc) => {
                if delta_m <= dc {
                    Region::Hertz
                } else {
                    Region::Plastic
                }
            }
            Degenerate::HertzOnly => Region::Hertz,
        }
    }

    /// Loading force at approach `delta_m` (paper Eq. 1); 0 for δ ≤ 0.
    pub fn force(&self, delta_m: f64) -> f64 {
        if delta_m <= 0.0 {
            return 0.0;
        }
        match self.region(delta_m) {
            Region::Hertz => hertz_force(self.e_star_pa, self.radius_m, delta_m),
            Region::Mixed => {
                delta_m * (self.alpha + self.beta * delta_m.ln())
                    + self.gamma * (delta_m - self.delta_y_m) * (self.fit.delta_p_m - delta_m)
            }
            Region::Plastic => self.plastic_line(delta_m),
        }
    }

    /// Tangent stiffness dF/dδ of the loading curve at `delta_m`, N/m.
    pub fn stiffness(&self, delta_m: f64) -> f64 {
        if delta_m <= 0.0 {
            return 0.0;
        }
        match self.region(delta_m) {
            Region::Hertz => 2.0 * self.e_star_pa * (self.radius_m * delta_m).sqrt(),
            Region::Mixed => {
                self.alpha
                    + self.beta * (delta_m.ln() + 1.0)
                    + self.gamma * (self.fit.delta_p_m + self.delta_y_m - 2.0 * delta_m)
            }
            Region::Plastic => self.p0_pa * PI * 2.0 * self.radius_m,
        }
    }

    /// The region-III line p0 π (2 r δ + c2), N.
    fn plastic_line(&self, delta_m: f64) -> f64 {
        self.p0_pa * PI * (2.0 * self.radius_m * delta_m + self.fit.c2_m2)
    }
}

/// Per-contact memory for unloading and reloading (docs/physics.md §3).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactHistory {
    /// Largest approach reached so far, m.
    pub delta_max_m: f64,
    /// Force the unloading curve passes through at δmax (its peak), N.
    pub force_max_n: f64,
    /// Whether loading ever left region I (then unloading is plastic, else Hertz).
    pub yielded: bool,
    /// Radius of curvature of the unloaded contact Rp, m (0 until first unloading).
    pub unloading_radius_m: f64,
    /// Residual approach δr at which the unloading force vanishes, m.
    pub residual_delta_m: f64,
    /// Largest force reached on the virgin (loading) curve, N.
    pub peak_force_n: f64,
    /// Largest approach speed δ̇ while loading on the virgin curve, m/s.
    pub peak_loading_speed_m_s: f64,
    /// Net work done on the contact so far, ∮F dδ by the trapezoidal rule over committed steps, J.
    pub work_j: f64,
    /// Work done while loading on the virgin curve since the last turning point, J.
    pub loading_work_j: f64,
    /// Approach of the last committed evaluation, m.
    pub last_delta_m: f64,
    /// Force of the last committed evaluation, N.
    pub last_force_n: f64,
}

/// How the elastoplastic law unloads after loading (docs/physics.md §3), scene key `unloading`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Unloading {
    /// Thornton's curve from the dynamic state: Fmax the largest force reached, Rp and δr with the
    /// rate-hardened yield stress of that state ([`BurgoyneDaraio::state_yield_stress`]), less
    /// the energy left in elastic vibrations (Hunter's scaling, [`VIBRATION_LOSS_COEFFICIENT`]).
    /// Default.
    #[default]
    Dynamic,
    /// Thornton's curve from the static loading curve at δmax (σy* = σy at the turning point):
    /// shpb's rule before issue 17.
    Static,
    /// As the authors' `f_contact.m`: Fmax the largest force reached, Rp with the static σy and Fy.
    Authors,
    /// The energy [`Unloading::Dynamic`] returns, on a Thornton curve that starts from the force
    /// at the turn (the static loading curve at δmax, which the rate-dependent loading force
    /// reaches as the approach rate vanishes) instead of the largest force reached: the force is
    /// continuous at the turning point and restitution is the dynamic rule's (docs/physics.md §3,
    /// "A continuous turn").
    DynamicContinuous,
}

impl Unloading {
    /// All rules with their scene names.
    pub const ALL: [(&'static str, Unloading); 4] = [
        ("dynamic", Unloading::Dynamic),
        ("static", Unloading::Static),
        ("authors", Unloading::Authors),
        ("dynamic-continuous", Unloading::DynamicContinuous),
    ];

    /// Whether the rule unloads from the rate-hardened state with the vibration loss
    /// ([`Unloading::Dynamic`] and [`Unloading::DynamicContinuous`]).
    pub fn is_dynamic(self) -> bool {
        matches!(self, Unloading::Dynamic | Unloading::DynamicContinuous)
    }
}

/// Coefficient k of the energy an impact leaves in elastic vibrations of the spheres,
/// W = k (u/c0)^{3/5} W_load (u the largest loading approach speed, c0 = √(E/ρ)): the exponent is
/// Hunter's (J. Mech. Phys. Solids 5, 162 (1957), whose half-space value is k = 1.04); k = 0.70 is
/// fitted on the authors' eight dynamic-FEM restitution values (`tests/data/dynamic_fem/restitution.csv`,
/// 1–100 m/s, plastic and Johnson–Cook; docs/physics.md §3).
pub const VIBRATION_LOSS_COEFFICIENT: f64 = 0.70;

/// Energy returned by the Hertz-shaped unloading curve through (δmax, Fmax) with elastic recovery
/// δe = δmax − δr: ∫ (4/3) E* √Rp x^{3/2} dx from 0 to δe = (2/5) Fmax δe, J.
fn unloading_energy_j(force_max_n: f64, recovery_m: f64) -> f64 {
    0.4 * force_max_n * recovery_m
}

/// What a contact law returns for one evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactEval {
    /// Contact force, N (≥ 0).
    pub force_n: f64,
    /// Yield stress in effect (σy* while loading with rate dependence), Pa.
    pub yield_stress_pa: f64,
    /// Global strain rate of paper Eq. 3, 1/s (≥ 0).
    pub strain_rate_per_s: f64,
}

/// A force law between two spheres that owns the type of its memory (`State`): Hertz needs
/// none, the elastoplastic law keeps its Thornton unloading state ([`ContactHistory`]); a new
/// unloading rule brings its own state without touching the solvers, which see a law only as a
/// [`Contact`] (law and state together).
pub trait ContactLaw: Send + Sync + Clone + 'static {
    /// What the law remembers between evaluations (reset to `Default` before contact).
    type State: Clone + Default + Send + Sync + std::fmt::Debug + 'static;

    /// Short name used in scenes and output (`burgoyne-daraio`, `rate-independent`, `hertz`).
    fn name(&self) -> &'static str;

    /// Force at approach `delta_m` with approach speed `approach_speed_m_s` (δ̇), updating `state`.
    fn evaluate(
        &self,
        state: &mut Self::State,
        delta_m: f64,
        approach_speed_m_s: f64,
    ) -> ContactEval;

    /// The virgin loading force at `delta_m` under a constant strain rate (no history).
    fn loading_force(&self, delta_m: f64, strain_rate_per_s: f64) -> f64;

    /// The force [`ContactLaw::evaluate`] returns at `delta_m` and δ̇ = `approach_speed_m_s` while
    /// [`ContactLaw::is_loading`] holds, the same number without a state to update (the trial
    /// evaluations of the implicit contact solves).
    fn virgin_force(&self, delta_m: f64, approach_speed_m_s: f64) -> f64;

    /// Whether `delta_m` loads the contact on its virgin curve (beyond any approach reached before).
    fn is_loading(&self, state: &Self::State, delta_m: f64) -> bool;

    /// Approach below which the contact carries no force, given its memory (δr), m.
    fn zero_force_approach(&self, state: &Self::State) -> f64;

    /// Whether the law has a yield stress to report (false for elastic Hertz).
    fn has_yield_stress(&self) -> bool {
        true
    }

    /// Whether the force depends on the approach speed (then solvers treat the speed implicitly).
    fn is_rate_dependent(&self) -> bool {
        false
    }
}

/// A contact as the solvers see it: a [`ContactLaw`] together with its memory, behind one
/// object-safe interface (what a contact joint of a chain or the two-sphere DEM holds).
pub trait Contact: Send + Sync {
    /// The law's name ([`ContactLaw::name`]).
    fn name(&self) -> &'static str;

    /// Evaluates and commits: force at `delta_m` and approach speed δ̇, updating the memory.
    fn evaluate(&mut self, delta_m: f64, approach_speed_m_s: f64) -> ContactEval;

    /// Evaluates without committing (for the implicit solves of a step), memory untouched.
    fn trial(&self, delta_m: f64, approach_speed_m_s: f64) -> ContactEval;

    /// `trial(delta_m, approach_speed_m_s).force_n`, the same number, cheaper while loading
    /// ([`ContactLaw::virgin_force`]: no copy of the memory, no bookkeeping, only the parts of the
    /// loading curve the approach needs).
    fn trial_force(&self, delta_m: f64, approach_speed_m_s: f64) -> f64;

    /// The virgin loading force at `delta_m` under a constant strain rate ([`ContactLaw::loading_force`]).
    fn loading_force(&self, delta_m: f64, strain_rate_per_s: f64) -> f64;

    /// Whether `delta_m` loads the contact on its virgin curve ([`ContactLaw::is_loading`]).
    fn is_loading(&self, delta_m: f64) -> bool;

    /// Approach below which the contact carries no force now (δr), m.
    fn zero_force_approach(&self) -> f64;

    /// Whether the law has a yield stress to report ([`ContactLaw::has_yield_stress`]).
    fn has_yield_stress(&self) -> bool;

    /// Whether the force depends on the approach speed ([`ContactLaw::is_rate_dependent`]).
    fn is_rate_dependent(&self) -> bool;

    /// The same law with no memory (a contact that never touched).
    fn fresh(&self) -> Box<dyn Contact>;
}

/// A contact law with its memory: the one implementation of [`Contact`].
#[derive(Debug, Clone)]
pub struct Stateful<L: ContactLaw> {
    /// The law.
    pub law: L,
    /// Its memory.
    pub state: L::State,
}

impl<L: ContactLaw> Stateful<L> {
    /// The law with a fresh (default) memory.
    pub fn new(law: L) -> Stateful<L> {
        Stateful {
            law,
            state: L::State::default(),
        }
    }
}

impl<L: ContactLaw> Contact for Stateful<L> {
    fn name(&self) -> &'static str {
        self.law.name()
    }

    fn evaluate(&mut self, delta_m: f64, approach_speed_m_s: f64) -> ContactEval {
        count_evaluation(true);
        self.law
            .evaluate(&mut self.state, delta_m, approach_speed_m_s)
    }

    fn trial(&self, delta_m: f64, approach_speed_m_s: f64) -> ContactEval {
        count_evaluation(false);
        self.law
            .evaluate(&mut self.state.clone(), delta_m, approach_speed_m_s)
    }

    fn trial_force(&self, delta_m: f64, approach_speed_m_s: f64) -> f64 {
        count_evaluation(false);
        if self.law.is_loading(&self.state, delta_m) {
            self.law.virgin_force(delta_m, approach_speed_m_s)
        } else {
            self.law
                .evaluate(&mut self.state.clone(), delta_m, approach_speed_m_s)
                .force_n
        }
    }

    fn loading_force(&self, delta_m: f64, strain_rate_per_s: f64) -> f64 {
        self.law.loading_force(delta_m, strain_rate_per_s)
    }

    fn is_loading(&self, delta_m: f64) -> bool {
        self.law.is_loading(&self.state, delta_m)
    }

    fn zero_force_approach(&self) -> f64 {
        self.law.zero_force_approach(&self.state)
    }

    fn has_yield_stress(&self) -> bool {
        self.law.has_yield_stress()
    }

    fn is_rate_dependent(&self) -> bool {
        self.law.is_rate_dependent()
    }

    fn fresh(&self) -> Box<dyn Contact> {
        Box::new(Stateful::new(self.law.clone()))
    }
}

/// Plain elastic Hertz contact (paper Eq. 1, region I, for all δ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hertz {
    /// Effective modulus, Pa.
    pub e_star_pa: f64,
    /// Effective radius, m.
    pub radius_m: f64,
    /// r1 + r2 for reporting the strain rate, m.
    pub sum_of_radii_m: f64,
}

impl ContactLaw for Hertz {
    type State = ();

    fn name(&self) -> &'static str {
        "hertz"
    }

    fn evaluate(&self, _state: &mut (), delta_m: f64, approach_speed_m_s: f64) -> ContactEval {
        ContactEval {
            force_n: hertz_force(self.e_star_pa, self.radius_m, delta_m),
            yield_stress_pa: f64::INFINITY,
            strain_rate_per_s: approach_speed_m_s.abs() / self.sum_of_radii_m,
        }
    }

    fn loading_force(&self, delta_m: f64, _strain_rate_per_s: f64) -> f64 {
        hertz_force(self.e_star_pa, self.radius_m, delta_m)
    }

    fn virgin_force(&self, delta_m: f64, _approach_speed_m_s: f64) -> f64 {
        hertz_force(self.e_star_pa, self.radius_m, delta_m)
    }

    fn is_loading(&self, _state: &(), delta_m: f64) -> bool {
        delta_m > 0.0
    }

    fn zero_force_approach(&self, _state: &()) -> f64 {
        0.0
    }

    fn has_yield_stress(&self) -> bool {
        false
    }
}

/// The Burgoyne–Daraio elastoplastic law: Eq. 1 loading, Johnson–Cook σy* from the global strain
/// rate (Eqs. 2–3) when `rate_dependent`, Thornton unloading/reloading (docs/physics.md §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BurgoyneDaraio {
    /// Effective properties of the pair.
    pub props: ContactProperties,
    /// Whether σy* follows the strain rate (false: the paper's "model without strain rate dependence").
    pub rate_dependent: bool,
    /// Form of region II.
    pub region2: Region2Form,
    /// Unloading rule.
    pub unloading: Unloading,
    static_curve: LoadingCurve,
}

impl BurgoyneDaraio {
    /// The law for a pair with the given effective properties (C¹ region II).
    pub fn new(props: ContactProperties, rate_dependent: bool) -> BurgoyneDaraio {
        BurgoyneDaraio::with_form(props, rate_dependent, Region2Form::Smooth)
    }

    /// The law with the chosen form of region II (default unloading).
    pub fn with_form(
        props: ContactProperties,
        rate_dependent: bool,
        region2: Region2Form,
    ) -> BurgoyneDaraio {
        BurgoyneDaraio::with_options(props, rate_dependent, region2, Unloading::default())
    }

    /// The law with the chosen form of region II and unloading rule.
    pub fn with_options(
        props: ContactProperties,
        rate_dependent: bool,
        region2: Region2Form,
        unloading: Unloading,
    ) -> BurgoyneDaraio {
        BurgoyneDaraio {
            props,
            rate_dependent,
            region2,
            unloading,
            static_curve: LoadingCurve::with_form(
                props.e_star_pa,
                props.radius_m,
                props.yield_stress_pa,
                region2,
            ),
        }
    }

    /// The quasi-static loading curve (σy not rate-hardened).
    pub fn static_curve(&self) -> &LoadingCurve {
        &self.static_curve
    }

    /// Global strain rate ε̇ = |δ̇| / (r1 + r2) while loading, else 0 (paper Eq. 3).
    pub fn strain_rate(&self, approach_speed_m_s: f64) -> f64 {
        if approach_speed_m_s > 0.0 {
            approach_speed_m_s / self.props.sum_of_radii_m
        } else {
            0.0
        }
    }

    /// Yield stress in effect at strain rate `rate` (σy* of Eq. 2, or σy when rate independent).
    pub fn yield_stress(&self, rate_per_s: f64) -> f64 {
        if self.rate_dependent {
            self.props
                .rate
                .dynamic_yield_stress(self.props.yield_stress_pa, rate_per_s)
        } else {
            self.props.yield_stress_pa
        }
    }

    /// The loading curve at strain rate `rate` (re-evaluated, not integrated: docs/physics.md §2).
    pub fn curve_at(&self, rate_per_s: f64) -> LoadingCurve {
        let s = self.yield_stress(rate_per_s);
        if s == self.props.yield_stress_pa {
            self.static_curve
        } else {
            LoadingCurve::with_form(self.props.e_star_pa, self.props.radius_m, s, self.region2)
        }
    }

    /// Thornton's unloading radius Rp and residual approach δr from (δmax, Fmax) with the static σy
    /// (docs/physics.md §3).
    pub fn thornton_unloading(&self, delta_max_m: f64, force_max_n: f64) -> (f64, f64) {
        self.thornton_unloading_at(delta_max_m, force_max_n, self.props.yield_stress_pa)
    }

    /// Thornton's Rp and δr from (δmax, Fmax) for the yield stress `yield_stress_pa` (σy, or the
    /// rate-hardened σy* of the dynamic rule), with Fy of that yield stress (docs/physics.md §3).
    pub fn thornton_unloading_at(
        &self,
        delta_max_m: f64,
        force_max_n: f64,
        yield_stress_pa: f64,
    ) -> (f64, f64) {
        let e = self.props.e_star_pa;
        let k = YIELD_ONSET_FACTOR * PI * yield_stress_pa;
        let fy = (1.0 / 6.0) * (self.props.radius_m / e).powi(2) * k * k * k;
        let rp = 4.0 * e * ((2.0 * force_max_n + fy) / (2.0 * k)).powf(1.5) / (3.0 * force_max_n);
        let dr = delta_max_m - (3.0 * force_max_n / (4.0 * e * rp.sqrt())).powf(2.0 / 3.0);
        (rp, dr.max(0.0))
    }

    /// Energy left in elastic vibrations by a loading that did `loading_work_j` at approach speeds up
    /// to `speed_m_s`: k (u/c0)^{3/5} W_load ([`VIBRATION_LOSS_COEFFICIENT`]), J.
    pub fn vibration_loss_j(&self, speed_m_s: f64, loading_work_j: f64) -> f64 {
        if !self.unloading.is_dynamic() || speed_m_s <= 0.0 || loading_work_j <= 0.0 {
            return 0.0;
        }
        VIBRATION_LOSS_COEFFICIENT
            * (speed_m_s / self.props.wave_speed_m_s).powf(0.6)
            * loading_work_j
    }

    /// The loading curve of Eq. 1 for yield stress `yield_stress_pa` (the static one for σy).
    fn curve_at_stress(&self, yield_stress_pa: f64) -> LoadingCurve {
        if yield_stress_pa == self.props.yield_stress_pa {
            self.static_curve
        } else {
            LoadingCurve::with_form(
                self.props.e_star_pa,
                self.props.radius_m,
                yield_stress_pa,
                self.region2,
            )
        }
    }

    /// The yield stress of the state a loading reached (docs/physics.md §3): the σ ≥ σy whose
    /// loading curve passes through (δmax, Fmax), so a rate-hardened loading is remembered by the
    /// curve it ended on. σy when Fmax is on or below the static curve; when Fmax reaches Hertz
    /// (no yield at any σ), the σ at which δmax = δy.
    pub fn state_yield_stress(&self, delta_max_m: f64, force_max_n: f64) -> f64 {
        let sy = self.props.yield_stress_pa;
        if !self.rate_dependent || force_max_n <= self.static_curve.force(delta_max_m) {
            return sy;
        }
        // δy(σ) = δmax at σ = √(4 δmax E*² / r) / (1.6 π): above it the curve is Hertz at δmax.
        let e = self.props.e_star_pa;
        let hertz_limit =
            (4.0 * delta_max_m * e * e / self.props.radius_m).sqrt() / (YIELD_ONSET_FACTOR * PI);
        if hertz_limit <= sy {
            return sy;
        }
        let below = |s: f64| self.curve_at_stress(s).force(delta_max_m) < force_max_n;
        let (lo, hi) = crate::numeric::bisect(
            sy.ln(),
            hertz_limit.ln(),
            100,
            |lo, hi| hi - lo < 1e-13,
            |x| below(x.exp()),
        );
        (0.5 * (lo + hi)).exp()
    }

    /// Sets up the unloading curve at a turning point (docs/physics.md §3): the peak it starts
    /// from and the elastic recovery δe by the chosen rule, then δe shortened by the vibration
    /// loss and so that the curve returns no more than the contact has absorbed (passivity).
    fn turn(&self, h: &mut ContactHistory) {
        let (fmax, recovery) = match self.unloading {
            Unloading::Static => {
                let f = self.static_curve.force(h.delta_max_m);
                h.yielded = self.static_curve.region(h.delta_max_m) != Region::Hertz;
                if h.yielded {
                    let (_, dr) = self.thornton_unloading(h.delta_max_m, f);
                    (f, h.delta_max_m - dr)
                } else {
                    // Elastic: back down the Hertz curve, exactly conservative.
                    h.force_max_n = f;
                    h.unloading_radius_m = self.props.radius_m;
                    h.residual_delta_m = 0.0;
                    return;
                }
            }
            Unloading::Authors | Unloading::Dynamic | Unloading::DynamicContinuous => {
                // The largest force reached (never below the force at δmax: both are set
                // together while loading).
                let f = h.peak_force_n;
                let sy = if self.unloading.is_dynamic() {
                    let s = self.state_yield_stress(h.delta_max_m, f);
                    h.yielded = self.curve_at_stress(s).region(h.delta_max_m) != Region::Hertz;
                    s
                } else {
                    self.props.yield_stress_pa
                };
                if h.yielded {
                    let (_, dr) = self.thornton_unloading_at(h.delta_max_m, f, sy);
                    (f, h.delta_max_m - dr)
                } else if self.unloading == Unloading::Authors {
                    h.force_max_n = f;
                    h.unloading_radius_m = self.props.radius_m;
                    h.residual_delta_m = 0.0;
                    return;
                } else {
                    // Never yielded: Hertzian recovery of the whole approach, from the peak force.
                    (f, h.delta_max_m)
                }
            }
        };
        // What the curve would return, never more than the contact absorbed (passivity for any
        // region II and rate history); then the vibration loss W_vib comes out of it, saturating
        // so that it never takes all: W_ret = W_el² / (W_el + W_vib) ≈ W_el − W_vib when small.
        let elastic = unloading_energy_j(fmax, recovery.min(h.delta_max_m))
            .min(h.work_j)
            .max(0.0);
        let loss = self.vibration_loss_j(h.peak_loading_speed_m_s, h.loading_work_j);
        let returned = if loss > 0.0 {
            elastic * elastic / (elastic + loss)
        } else {
            elastic
        };
        // The continuous rule returns that energy from the force at the turn, over a longer
        // recovery (at most δmax: beyond, less comes back).
        let fmax = match self.unloading {
            Unloading::DynamicContinuous => self.static_curve.force(h.delta_max_m).min(fmax),
            _ => fmax,
        };
        let recovery = (returned / (0.4 * fmax)).min(h.delta_max_m);
        // Keep a curve (a vanishing recovery would be a vertical drop of the force).
        let recovery = recovery.max(1e-6 * h.delta_max_m);
        h.force_max_n = fmax;
        h.residual_delta_m = h.delta_max_m - recovery;
        // F = (4/3) E* √Rp δe^{3/2} = Fmax.
        let sqrt_rp = 3.0 * fmax / (4.0 * self.props.e_star_pa * recovery.powf(1.5));
        h.unloading_radius_m = sqrt_rp * sqrt_rp;
    }
}

impl ContactLaw for BurgoyneDaraio {
    type State = ContactHistory;

    fn name(&self) -> &'static str {
        if self.rate_dependent {
            "burgoyne-daraio"
        } else {
            "rate-independent"
        }
    }

    fn evaluate(
        &self,
        h: &mut ContactHistory,
        delta_m: f64,
        approach_speed_m_s: f64,
    ) -> ContactEval {
        let rate = self.strain_rate(approach_speed_m_s);
        let eval = if delta_m >= h.delta_max_m && delta_m > 0.0 {
            // Loading on the virgin curve at the current rate.
            let curve = self.curve_at(rate);
            let f = curve.force(delta_m);
            h.delta_max_m = delta_m;
            h.force_max_n = f;
            h.peak_force_n = h.peak_force_n.max(f);
            h.peak_loading_speed_m_s = h.peak_loading_speed_m_s.max(approach_speed_m_s);
            if curve.region(delta_m) != Region::Hertz {
                h.yielded = true;
            }
            h.unloading_radius_m = 0.0;
            h.residual_delta_m = 0.0;
            h.loading_work_j += 0.5 * (h.last_force_n + f) * (delta_m - h.last_delta_m);
            ContactEval {
                force_n: f,
                yield_stress_pa: curve.yield_stress_pa,
                strain_rate_per_s: rate,
            }
        } else {
            // Unloading or reloading below δmax: elastic on the unloading curve.
            if h.unloading_radius_m == 0.0 && h.delta_max_m > 0.0 {
                self.turn(h);
                h.loading_work_j = 0.0;
                h.peak_loading_speed_m_s = 0.0;
            }
            let f = if h.unloading_radius_m > 0.0 {
                hertz_force(
                    self.props.e_star_pa,
                    h.unloading_radius_m,
                    delta_m - h.residual_delta_m,
                )
            } else {
                0.0
            };
            ContactEval {
                force_n: f,
                yield_stress_pa: self.props.yield_stress_pa,
                strain_rate_per_s: rate,
            }
        };
        h.work_j += 0.5 * (h.last_force_n + eval.force_n) * (delta_m.max(0.0) - h.last_delta_m);
        h.last_delta_m = delta_m.max(0.0);
        h.last_force_n = eval.force_n;
        eval
    }

    fn loading_force(&self, delta_m: f64, strain_rate_per_s: f64) -> f64 {
        let s = self.yield_stress(strain_rate_per_s);
        if s == self.props.yield_stress_pa {
            self.static_curve.force(delta_m)
        } else {
            LoadingCurve::force_for(
                self.props.e_star_pa,
                self.props.radius_m,
                s,
                self.region2,
                delta_m,
            )
        }
    }

    fn virgin_force(&self, delta_m: f64, approach_speed_m_s: f64) -> f64 {
        self.loading_force(delta_m, self.strain_rate(approach_speed_m_s))
    }

    fn is_loading(&self, h: &ContactHistory, delta_m: f64) -> bool {
        delta_m >= h.delta_max_m && delta_m > 0.0
    }

    fn zero_force_approach(&self, h: &ContactHistory) -> f64 {
        h.residual_delta_m.max(0.0)
    }

    fn is_rate_dependent(&self) -> bool {
        self.rate_dependent && self.props.rate.c != 0.0
    }
}

/// Effective properties of a pair as used by the contact law (paper Sec. II; authors' code for
/// dissimilar spheres: the yield stress and rate hardening of the weaker sphere).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactProperties {
    /// Effective modulus E* = [(1−ν1²)/E1 + (1−ν2²)/E2]⁻¹, Pa.
    pub e_star_pa: f64,
    /// Effective radius r = (1/r1 + 1/r2)⁻¹, m.
    pub radius_m: f64,
    /// r1 + r2, the length in the global strain rate of paper Eq. 3, m.
    pub sum_of_radii_m: f64,
    /// Quasi-static yield stress min(σy1, σy2), Pa.
    pub yield_stress_pa: f64,
    /// Rate hardening of the sphere with the smaller yield stress (paper Eq. 2).
    pub rate: crate::material::JohnsonCook,
    /// Bar wave speed c0 = √(E/ρ) of the slower sphere, m/s (vibration loss, docs/physics.md §3).
    pub wave_speed_m_s: f64,
}

/// A contact law with its own parameters (docs/physics.md §1–§3): the law, the form of region II
/// and the unloading rule (the last two ignored by Hertz). One value travels from the scene to
/// every contact built from it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LawSpec {
    /// The law (`law` scene key).
    pub kind: LawKind,
    /// Form of region II of the loading law (`region2`).
    pub region2: Region2Form,
    /// Unloading rule (`unloading`).
    pub unloading: Unloading,
}

impl LawSpec {
    /// The law `kind` with the default region II (smooth) and unloading (dynamic).
    pub fn of(kind: LawKind) -> LawSpec {
        LawSpec {
            kind,
            ..LawSpec::default()
        }
    }

    /// Builds the law with its memory for a pair's effective properties.
    pub fn build(self, props: ContactProperties) -> Box<dyn Contact> {
        self.kind.build_options(props, self.region2, self.unloading)
    }
}

/// The contact laws a scene can select with `law = "..."`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LawKind {
    /// Eq. 1 + Johnson–Cook + Thornton unloading (the paper's model).
    #[default]
    BurgoyneDaraio,
    /// Eq. 1 + Thornton unloading with the static σy (the paper's Fig. 4 black curves).
    RateIndependent,
    /// Elastic Hertz throughout.
    Hertz,
}

impl LawKind {
    /// All selectable laws with their scene names.
    pub const ALL: [(&'static str, LawKind); 3] = [
        ("burgoyne-daraio", LawKind::BurgoyneDaraio),
        ("rate-independent", LawKind::RateIndependent),
        ("hertz", LawKind::Hertz),
    ];

    /// Builds the law for a pair's effective properties (C¹ region II).
    pub fn build(self, props: ContactProperties) -> Box<dyn Contact> {
        self.build_with(props, Region2Form::Smooth)
    }

    /// Builds the law with the chosen form of region II (ignored by Hertz) and default unloading.
    pub fn build_with(self, props: ContactProperties, region2: Region2Form) -> Box<dyn Contact> {
        self.build_options(props, region2, Unloading::default())
    }

    /// Builds the law with the chosen form of region II and unloading rule (both ignored by Hertz).
    pub fn build_options(
        self,
        props: ContactProperties,
        region2: Region2Form,
        unloading: Unloading,
    ) -> Box<dyn Contact> {
        match self {
            LawKind::BurgoyneDaraio => Box::new(Stateful::new(BurgoyneDaraio::with_options(
                props, true, region2, unloading,
            ))),
            LawKind::RateIndependent => Box::new(Stateful::new(BurgoyneDaraio::with_options(
                props, false, region2, unloading,
            ))),
            LawKind::Hertz => Box::new(Stateful::new(Hertz {
                e_star_pa: props.e_star_pa,
                radius_m: props.radius_m,
                sum_of_radii_m: props.sum_of_radii_m,
            })),
        }
    }
}

#[cfg(test)]
mod tests {
    //! Every law against its analytic form: Hertz (docs/physics.md §1), Eq. 1 continuity at δy
    //! and δp, the C¹ region II, Johnson–Cook hardening (§2) and Thornton unloading (§3).
    use super::*;
    use crate::material::JohnsonCook;
    use approx::assert_relative_eq;

    /// Two 6.35 mm SS440c spheres (E 200 GPa, ν 0.28, σy 1.9 GPa, C 0.035): the paper's pair.
    fn ss440c() -> ContactProperties {
        let plane = 200e9 / (1.0 - 0.28 * 0.28);
        ContactProperties {
            e_star_pa: plane / 2.0,
            radius_m: 3.175e-3 / 2.0,
            sum_of_radii_m: 6.35e-3,
            yield_stress_pa: 1.9e9,
            rate: JohnsonCook {
                c: 0.035,
                reference_rate_per_s: 1e-3,
            },
            wave_speed_m_s: (204e9f64 / 7800.0).sqrt(),
        }
    }

    /// The lazy evaluations the implicit solves use are the full ones, bit for bit: the loading
    /// curve's force in every region, in both forms and when region II is missing (a yield stress
    /// so high that δp ≤ δy), and a contact's trial force while loading, unloading and reloading.
    #[test]
    fn lazy_forces_are_the_full_evaluations_bit_for_bit() {
        let p = ss440c();
        let (e, r) = (p.e_star_pa, p.radius_m);
        for sigma in [0.5e9, p.yield_stress_pa, 3.0e9, 2.0e10, 1.0e11] {
            for form in [Region2Form::Smooth, Region2Form::Published] {
                let curve = LoadingCurve::with_form(e, r, sigma, form);
                for i in 0..400 {
                    let d = 1e-9 * 1.05f64.powi(i) - 2e-9;
                    let lazy = LoadingCurve::force_for(e, r, sigma, form, d);
                    assert_eq!(
                        lazy.to_bits(),
                        curve.force(d).to_bits(),
                        "{sigma} {form:?} {d}"
                    );
                }
            }
        }
        for law in [
            LawKind::BurgoyneDaraio,
            LawKind::RateIndependent,
            LawKind::Hertz,
        ] {
            let mut c = law.build(p);
            // Load, unload part way, reload past the maximum.
            let path = (0..60)
                .map(|i| 4e-6 * i as f64)
                .chain((0..20).map(|i| 236e-6 - 3e-6 * i as f64))
                .chain((0..40).map(|i| 180e-6 + 4e-6 * i as f64));
            for d in path {
                for u in [0.0, 0.5, 3.0, 20.0] {
                    let (a, b) = (c.trial_force(d, u), c.trial(d, u).force_n);
                    assert_eq!(a.to_bits(), b.to_bits(), "{law:?} δ {d} δ̇ {u}");
                }
                c.evaluate(d, 3.0);
            }
        }
    }

    #[test]
    fn hertz_force_is_the_derivative_of_its_energy_and_elastic_on_unloading() {
        let p = ss440c();
        let (e, r) = (p.e_star_pa, p.radius_m);
        let d = 20e-6;
        assert_relative_eq!(
            hertz_force(e, r, d),
            4.0 / 3.0 * e * r.sqrt() * d.powf(1.5),
            max_relative = 1e-14
        );
        let h = 1e-10;
        let numeric = (hertz_energy(e, r, d + h) - hertz_energy(e, r, d - h)) / (2.0 * h);
        assert_relative_eq!(numeric, hertz_force(e, r, d), max_relative = 1e-6);
        let mut contact = LawKind::Hertz.build(p);
        let up = contact.evaluate(d, 1.0).force_n;
        let down = contact.evaluate(0.5 * d, -1.0).force_n;
        assert_relative_eq!(up, hertz_force(e, r, d), max_relative = 1e-12);
        assert_relative_eq!(down, hertz_force(e, r, 0.5 * d), max_relative = 1e-12);
    }

    #[test]
    fn eq1_is_continuous_at_yield_and_at_full_plasticity_in_both_forms() {
        let p = ss440c();
        for form in [Region2Form::Smooth, Region2Form::Published] {
            let c = LoadingCurve::with_form(p.e_star_pa, p.radius_m, p.yield_stress_pa, form);
            assert_eq!(c.degenerate, Degenerate::No);
            let (dy, dp) = (c.delta_y_m, c.fit.delta_p_m);
            assert!(dy < dp);
            let eps = 1e-9;
            assert_relative_eq!(c.force(dy * (1.0 - eps)), c.force_y_n, max_relative = 1e-6);
            assert_relative_eq!(c.force(dy * (1.0 + eps)), c.force_y_n, max_relative = 1e-6);
            assert_relative_eq!(c.force(dp * (1.0 - eps)), c.force_p_n, max_relative = 1e-6);
            assert_relative_eq!(c.force(dp * (1.0 + eps)), c.force_p_n, max_relative = 1e-6);
            assert_eq!(c.region(0.5 * dy), Region::Hertz);
            assert_eq!(c.region(2.0 * dp), Region::Plastic);
            // Region III is the straight line F = p0 π (2 r δ + c2).
            let slope = (c.force(3.0 * dp) - c.force(2.0 * dp)) / dp;
            assert_relative_eq!(
                slope,
                2.0 * PI * c.fit.c1 * p.yield_stress_pa * p.radius_m,
                max_relative = 1e-9
            );
        }
    }

    #[test]
    fn the_smooth_region2_is_c1_at_yield_and_the_published_one_is_not() {
        let p = ss440c();
        let slope = |c: &LoadingCurve, d: f64| {
            let h = 1e-6 * d;
            (c.force(d + h) - c.force(d - h)) / (2.0 * h)
        };
        let smooth = LoadingCurve::new(p.e_star_pa, p.radius_m, p.yield_stress_pa);
        let published = LoadingCurve::with_form(
            p.e_star_pa,
            p.radius_m,
            p.yield_stress_pa,
            Region2Form::Published,
        );
        let dy = smooth.delta_y_m;
        let jump = |c: &LoadingCurve| {
            (slope(c, dy * (1.0 + 1e-3)) - slope(c, dy * (1.0 - 1e-3))).abs() / slope(c, dy)
        };
        assert!(jump(&smooth) < 2e-3, "smooth jump {}", jump(&smooth));
        // docs/physics.md §1: the paper's form jumps by 13–17 % for the paper's materials.
        assert!(
            jump(&published) > 0.10,
            "published jump {}",
            jump(&published)
        );
    }

    #[test]
    fn johnson_cook_raises_the_loading_force_with_rate_and_not_below_the_reference_rate() {
        let law = BurgoyneDaraio::new(ss440c(), true);
        let d = 3.0 * law.static_curve().fit.delta_p_m;
        assert_eq!(law.loading_force(d, 1e-4), law.loading_force(d, 0.0));
        let (slow, fast) = (law.loading_force(d, 1.0), law.loading_force(d, 1e4));
        assert!(fast > slow);
        assert_relative_eq!(
            law.yield_stress(1e4),
            1.9e9 * (1.0 + 0.035 * (1e4f64 / 1e-3).ln()),
            max_relative = 1e-12
        );
        let independent = BurgoyneDaraio::new(ss440c(), false);
        assert_eq!(
            independent.loading_force(d, 1e4),
            independent.loading_force(d, 0.0)
        );
    }

    #[test]
    fn thornton_unloading_starts_at_the_peak_force_and_ends_at_the_residual_approach() {
        let law =
            BurgoyneDaraio::with_options(ss440c(), false, Region2Form::Smooth, Unloading::Static);
        let mut h = ContactHistory::default();
        let dmax = 2.0 * law.static_curve().fit.delta_p_m;
        let fmax = law.evaluate(&mut h, dmax, 1.0).force_n;
        assert!(h.yielded);
        let (rp, dr) = law.thornton_unloading(dmax, fmax);
        assert!(rp > 0.0 && dr > 0.0 && dr < dmax);
        // Unloading curve F = (4/3) E* √Rp (δ − δr)^{3/2} passes through (δmax, Fmax).
        let back = 4.0 / 3.0 * ss440c().e_star_pa * rp.sqrt() * (dmax - dr).powf(1.5);
        assert_relative_eq!(back, fmax, max_relative = 1e-9);
        // Passive: less force on the way down than on the way up, none below δr.
        let d = 0.5 * (dr + dmax);
        let down = law.evaluate(&mut h, d, -1.0).force_n;
        assert!(down < law.loading_force(d, 0.0));
        assert_eq!(law.evaluate(&mut h, 0.9 * dr, -1.0).force_n, 0.0);
        assert_relative_eq!(law.zero_force_approach(&h), dr, max_relative = 1e-12);
    }

    /// The authors' dynamic-FEM sphere material (E 200 GPa, ν 0.3, ρ 7650 kg/m³, σy 1896 MPa,
    /// Johnson–Cook C = 0.05 at 1e-3 1/s), 6.35 mm spheres: `restitution.csv`'s set-up.
    fn fem_steel() -> crate::specimen::SpherePair {
        crate::specimen::SpherePair::paper(crate::material::Material {
            name: "fem-steel".into(),
            density_kg_m3: 7650.0,
            youngs_modulus_pa: 200e9,
            poisson_ratio: 0.3,
            yield_stress_pa: 1896e6,
            rate: JohnsonCook {
                c: 0.05,
                reference_rate_per_s: 1e-3,
            },
        })
    }

    /// A free collision at `speed` with 2000 steps per Hertz contact time: (e, KE before, ∮F dδ).
    fn collide(
        pair: &crate::specimen::SpherePair,
        law: &dyn Contact,
        speed: f64,
    ) -> (f64, f64, f64) {
        let p = pair.contact_properties();
        let tc = crate::solver::hertz_impact_duration(
            pair.reduced_mass_kg(),
            p.e_star_pa,
            p.radius_m,
            speed,
        );
        let setup = crate::solver::CollisionSetup {
            velocity1_m_s: speed,
            velocity2_m_s: 0.0,
            dt_s: tc / 2000.0,
            max_time_s: 1000.0 * tc,
            output_every: 1000,
        };
        let r = crate::solver::collision(law, pair, &setup).expect("collision runs");
        (r.restitution, r.kinetic_energy_before_j, r.dissipated_j)
    }

    #[test]
    fn below_yield_the_dynamic_rule_loses_exactly_the_vibration_energy_and_static_none() {
        // An impact that stays in region I: the static rule unloads down the Hertz curve (e = 1
        // to round-off); the dynamic rule returns W²/(W + W_vib) of the loading work W, with
        // W_vib = k (v/c0)^{3/5} W, so e² = 1/(1 + k (v/c0)^{3/5}) (the largest approach speed
        // is the impact speed).
        let pair = fem_steel();
        let p = pair.contact_properties();
        let speed = 0.05;
        let stat = LawKind::BurgoyneDaraio.build_options(p, Region2Form::Smooth, Unloading::Static);
        let (e, _, _) = collide(&pair, stat.as_ref(), speed);
        assert_relative_eq!(e, 1.0, max_relative = 1e-9);
        let dynamic = LawKind::BurgoyneDaraio.build(p);
        let (e, _, _) = collide(&pair, dynamic.as_ref(), speed);
        let expected =
            1.0 / (1.0 + VIBRATION_LOSS_COEFFICIENT * (speed / p.wave_speed_m_s).powf(0.6)).sqrt();
        // The loading work is integrated over steps (second order at 2000 steps a contact).
        assert_relative_eq!(e, expected, max_relative = 1e-6);
    }

    #[test]
    fn rate_hardening_raises_restitution_under_the_dynamic_rule_as_in_the_fem() {
        // The authors' dynamic FEM: Johnson–Cook raises e over the plastic run by 0.11–0.13 at
        // 10–100 m/s. The static rule (shpb before issue 17) lowered it.
        let pair = fem_steel();
        let p = pair.contact_properties();
        for speed in [10.0, 50.0] {
            let e = |kind: LawKind, rule| {
                collide(
                    &pair,
                    kind.build_options(p, Region2Form::Smooth, rule).as_ref(),
                    speed,
                )
                .0
            };
            let dynamic = e(LawKind::BurgoyneDaraio, Unloading::Dynamic)
                - e(LawKind::RateIndependent, Unloading::Dynamic);
            assert!(dynamic > 0.08, "{speed} m/s: rise {dynamic}");
            let old = e(LawKind::BurgoyneDaraio, Unloading::Static)
                - e(LawKind::RateIndependent, Unloading::Static);
            assert!(old < 0.0, "{speed} m/s: static rule rise {old}");
        }
    }

    /// `dynamic-continuous` returns the dynamic rule's energy, so its restitution is the dynamic
    /// rule's (the collision steps the same loading; the unloading curves differ only in how
    /// they give the energy back), while its force at the turn is the static loading curve's at
    /// δmax (continuous with the rate-dependent loading force as the rate vanishes) where the
    /// dynamic rule jumps to the largest force reached.
    #[test]
    fn the_continuous_turn_keeps_the_dynamic_restitution_without_the_jump() {
        let pair = fem_steel();
        let p = pair.contact_properties();
        let e = |rule, speed| {
            collide(
                &pair,
                LawKind::BurgoyneDaraio
                    .build_options(p, Region2Form::Smooth, rule)
                    .as_ref(),
                speed,
            )
            .0
        };
        for speed in [10.0, 50.0, 100.0] {
            let (dynamic, continuous) = (
                e(Unloading::Dynamic, speed),
                e(Unloading::DynamicContinuous, speed),
            );
            // The unloading curves are integrated over steps: the returned energies agree to the
            // quadrature's second order, far below the 0.03 of the restitution checks.
            assert!(
                (continuous - dynamic).abs() < 2e-3,
                "{speed} m/s: e = {continuous} against {dynamic}"
            );
        }
        // Just above yield the longer recovery would pass δmax: capped there, less comes back.
        let (dynamic, continuous) = (
            e(Unloading::Dynamic, 1.0),
            e(Unloading::DynamicContinuous, 1.0),
        );
        assert!(
            continuous < dynamic,
            "1 m/s: {continuous} against {dynamic}"
        );
        // At a turn the continuous rule's curve starts at the static curve's force at δmax,
        // below the largest force reached.
        let law = BurgoyneDaraio::with_options(
            p,
            true,
            Region2Form::Smooth,
            Unloading::DynamicContinuous,
        );
        let mut h = ContactHistory::default();
        let delta = 20.0 * law.static_curve.delta_y_m;
        let mut peak: f64 = 0.0;
        let steps = 200;
        for i in 1..=steps {
            // Loading at an approach speed falling to zero.
            let d = delta * (i as f64 / steps as f64).sqrt();
            let speed = 10.0 * (1.0 - i as f64 / steps as f64) + 1e-9;
            peak = peak.max(law.evaluate(&mut h, d, speed).force_n);
        }
        let after = law.evaluate(&mut h, delta * (1.0 - 1e-12), -1e-3).force_n;
        let at_turn = law.static_curve.force(delta);
        assert_relative_eq!(after, at_turn, max_relative = 1e-6);
        assert!(after < peak, "{after} against the peak {peak}");
    }

    /// A material drawn by the passivity property tests.
    fn any_material() -> impl proptest::strategy::Strategy<Value = crate::material::Material> {
        use proptest::prelude::*;
        (
            1e3f64..2e4,
            50e9f64..400e9,
            0.2f64..0.4,
            100e6f64..3e9,
            0.0f64..0.1,
        )
            .prop_map(|(rho, e, nu, sy, c)| crate::material::Material {
                name: "drawn".into(),
                density_kg_m3: rho,
                youngs_modulus_pa: e,
                poisson_ratio: nu,
                yield_stress_pa: sy,
                rate: JohnsonCook {
                    c,
                    reference_rate_per_s: 1e-3,
                },
            })
    }

    fn any_options() -> impl proptest::strategy::Strategy<Value = (LawKind, Region2Form, Unloading)>
    {
        use proptest::prelude::*;
        (
            prop::sample::select(LawKind::ALL.map(|(_, k)| k).to_vec()),
            prop::sample::select(vec![Region2Form::Smooth, Region2Form::Published]),
            prop::sample::select(Unloading::ALL.map(|(_, u)| u).to_vec()),
        )
    }

    /// How far a collision may appear to exceed e = 1: when the passivity guard makes a contact
    /// return exactly what it absorbed, the trapezoidal sum of the discrete unloading differs from
    /// the curve's integral by O((Δt/tc)²) = 2.5e-7 at 2000 steps per contact (largest seen
    /// 3e-7). The unguarded published region II gave 7e-3 to 2.6e-2 (issue 17).
    const PASSIVE_WITHIN: f64 = 1e-6;

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(96))]

        /// Passivity of every law, region-II form and unloading rule in free collisions of two
        /// spheres (same or different materials and sizes) from 0.05 to 150 m/s: restitution
        /// ≤ 1 and dissipated energy ≥ 0, within [`PASSIVE_WITHIN`].
        #[test]
        fn every_law_is_passive_in_collisions(
            m1 in any_material(),
            m2 in any_material(),
            d1 in 1e-3f64..2e-2,
            d2 in 1e-3f64..2e-2,
            log_speed in (0.05f64).ln()..(150f64).ln(),
            (kind, form, rule) in any_options(),
        ) {
            let pair = crate::specimen::SpherePair {
                sphere1: crate::specimen::Sphere::full(m1, d1 / 2.0),
                sphere2: crate::specimen::Sphere::full(m2, d2 / 2.0),
            };
            let law = kind.build_options(pair.contact_properties(), form, rule);
            let (e, ke, dissipated) = collide(&pair, law.as_ref(), log_speed.exp());
            proptest::prop_assert!(e <= 1.0 + PASSIVE_WITHIN, "restitution {e}");
            proptest::prop_assert!(dissipated >= -PASSIVE_WITHIN * ke, "dissipated {dissipated} of {ke}");
        }

        /// Passivity under any history: along a random zig-zag of the approach (loading,
        /// unloading, reloading past δmax, at random rates) the net work ∮F dδ done on the
        /// contact never falls below zero beyond the trapezoidal rule's error (1e-6 of the work
        /// put in): a contact never returns more energy than it received.
        #[test]
        fn no_history_makes_a_contact_return_more_than_it_received(
            m in any_material(),
            (kind, form, rule) in any_options(),
            turns in proptest::collection::vec((0.0f64..1.0, -5.0f64..2.0), 1..8),
        ) {
            let pair = crate::specimen::SpherePair::paper(m);
            let p = pair.contact_properties();
            let mut law = kind.build_options(p, form, rule);
            let scale = 40.0 * LoadingCurve::new(p.e_star_pa, p.radius_m, p.yield_stress_pa).delta_y_m;
            let (mut delta, mut force, mut work, mut put_in) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
            for (target, log_speed) in turns {
                let target = target * scale;
                let speed = 10f64.powf(log_speed);
                // 2000 steps a leg: the trapezoidal rule's error is then below 1e-7 of the work.
                let n = 2000;
                let step = (target - delta) / n as f64;
                for _ in 0..n {
                    let next = delta + step;
                    let f = law.evaluate(next, step.signum() * speed).force_n;
                    let dw = 0.5 * (force + f) * (next - delta);
                    work += dw;
                    put_in += dw.max(0.0);
                    delta = next;
                    force = f;
                    proptest::prop_assert!(work >= -1e-6 * put_in, "net work {work} of {put_in}");
                }
            }
        }
    }
}
