//! Steps that end at a contact dashpot's force switches, for the Runge–Kutta steppers in
//! first-order form with contact events (`rk4-contact`, and the sixth-order method measured
//! against it, `crate::testing::Rk6Contact`). A dashpot's force jumps to γ ċ as a contact
//! closes (linear law) and has a kink where its clip starts; a step's later stages would carry
//! either into every stage state, which the bond's own correction cannot undo (order 2 instead
//! of 2.5). So a step is cut LATE after its first switch, so that its last stage alone sees the
//! new force, and the parts and steps after it correct that bond too, whose force is not smooth
//! just behind its start (`ContactEvents::correct_next`).

use super::stage_step::{finish_step, FixedStepScratch};
use super::{StepOutcome, StepSpan};
use crate::dofs::StepStates;
use crate::model::Model;

/// Most force switches one step is split at; one beyond them is corrected as any event.
const MAX_LOCATED: usize = 8;

/// A switch this close to either end of a step (as a fraction of it) is left to the correction.
const MIN_LOCATED: f64 = 1e-6;

/// How far after a switch a located step ends, as a fraction of the whole step.
const LATE: f64 = 1e-8;

/// A fixed-step stepper of `S` stages with contact events, as a located step drives it.
pub(crate) trait Staged<const S: usize> {
    /// The stages over `span` from `y`, the new state (uncorrected) left in the scratch.
    fn stages(&mut self, model: &Model, y: &[f64], span: StepSpan);

    /// Corrects the new state the stages left (the contact events) and copies it into `y`
    /// over `span`'s window.
    fn finish(&mut self, model: &Model, y: &mut [f64], span: StepSpan) {
        let s = self.scratch();
        finish_step(
            (s.contact.as_mut(), None),
            model,
            (y, &mut s.y_new),
            span.h,
            span.window,
        );
    }

    /// Its scratch, with the new state and the contact events.
    fn scratch(&mut self) -> &mut FixedStepScratch<S>;
}

/// One step of `stepper` over `span`: in parts at the force switches on a chain whose contacts
/// carry a dashpot, when it keeps contact events; whole otherwise.
pub(crate) fn step<const S: usize>(
    stepper: &mut impl Staged<S>,
    model: &Model,
    y: &mut [f64],
    span: StepSpan,
) -> StepOutcome {
    let events = stepper.scratch().contact.is_some();
    let dashpots = model.damping().is_some_and(|d| d.has_contact_dashpot());
    match events && dashpots {
        true => located_step(stepper, model, y, span),
        false => {
            stepper.stages(model, y, span);
            stepper.finish(model, y, span);
        }
    }
    StepOutcome::Accepted { h_next: span.h }
}

/// The step `span` of `stepper` in parts that end at its force switches; switches within
/// MIN_LOCATED of a part's ends (in the whole step's measure) are left to the correction.
fn located_step<const S: usize>(
    stepper: &mut impl Staged<S>,
    model: &Model,
    y: &mut [f64],
    span: StepSpan,
) {
    let mut rest = span;
    for _ in 0..MAX_LOCATED {
        stepper.stages(model, y, rest);
        let s = stepper.scratch();
        let contact = s
            .contact
            .as_mut()
            .expect("a located step keeps contact events");
        let away =
            |x: f64| x * rest.h > MIN_LOCATED * span.h && (1.0 - x) * rest.h > MIN_LOCATED * span.h;
        let states = StepStates {
            start: y,
            end: &s.y_new,
        };
        let switch = contact.first_switch(model, states, rest.h, rest.window);
        let Some((x, bond)) = switch.filter(|&(x, _)| away(x)) else {
            return stepper.finish(model, y, rest);
        };
        let part = StepSpan {
            h: x * rest.h + LATE * span.h,
            ..rest
        };
        stepper.stages(model, y, part);
        stepper.finish(model, y, part);
        if let Some(contact) = stepper.scratch().contact.as_mut() {
            contact.correct_next(bond, span.h);
        }
        rest = StepSpan {
            t: rest.t + part.h,
            h: rest.h - part.h,
            ..rest
        };
    }
    stepper.stages(model, y, rest);
    stepper.finish(model, y, rest);
}
