//! Scalar outputs of a level at the final time T (`[quantities]` of the scene), and their Richardson
//! estimates. Each output Q is a number per level; [`super::richardson::ScalarModel`] extrapolates the three
//! finest levels to Q* = Q₃ + (Q₃ − Q₂)/(r₃₂ᵖ − 1), the estimated error of level l is |Q_l − Q*| and its
//! GCI F_s |Q_l − Q*| (F_s = 1.25; 3 with two levels, where p is taken as the theoretical order).
//!
//! | name | value at T |
//! |---|---|
//! | `max_slip` | max over Γ_C edges of |u_τ(m_e)| |
//! | `stick_length` | Σ |e| over the Γ_C edges sticking in the last step |
//! | `contact_length` | Σ |e| over the Γ_C edges in contact (not separated) in the last step (normal unknowns) |
//! | `max_pressure` | max over Γ_C edges of p_e = P_e/|e| in the last step (normal unknowns) |
//! | `elastic_energy` | ½ a_h(u, u) |
//! | `traction_<x>_<y>` | σ_τ·τ = −μ_e/|e| on the Γ_C edge nearest to (x, y) |

use super::richardson::{asymptotic, ScalarModel, Verdict, FS_THREE, FS_TWO};
use super::Axis;
use crate::friction::EdgeState;
use crate::scene::{Outputs, Scene};
use crate::stepping::{Problem, StepResult};

/// The outputs a scene asks for (module doc), with the defaults of [`Outputs`].
pub fn selected(scene: &Scene) -> Outputs {
    scene.outputs.clone().unwrap_or(Outputs {
        max_slip: scene.has_contact(),
        stick_length: scene.has_contact(),
        contact_length: false,
        max_pressure: false,
        elastic_energy: true,
        traction_at: vec![],
    })
}

/// The theoretical order of an output along `size`: 2 for the elastic energy in h (½a_h(u_h,u_h) −
/// ½a(u,u) is quadratic in the O(h) energy error, by Galerkin orthogonality up to the nonconformity),
/// 1 for the energy in k (no orthogonality in time: linear in backward Euler's O(k) error) and 1 for the
/// others (values and tractions of CR fields on Γ_C, and the position of the stick–slip front, are O(h)
/// at best).
pub fn theoretical_order(name: &str, size: Axis) -> f64 {
    if name == "elastic_energy" && size == Axis::H {
        2.0
    } else {
        1.0
    }
}

/// Column names of the outputs, in order.
pub fn names(o: &Outputs) -> Vec<String> {
    let mut v = Vec::new();
    for (on, name) in [
        (o.max_slip, "max_slip"),
        (o.stick_length, "stick_length"),
        (o.contact_length, "contact_length"),
        (o.max_pressure, "max_pressure"),
        (o.elastic_energy, "elastic_energy"),
    ] {
        if on {
            v.push(name.to_string());
        }
    }
    v.extend(o.traction_at.iter().map(|x| format!("traction_{}_{}", x[0], x[1])));
    v
}

/// Distance from x to segment ab.
fn segment_distance(x: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (d, w) = ([b[0] - a[0], b[1] - a[1]], [x[0] - a[0], x[1] - a[1]]);
    let s = ((w[0] * d[0] + w[1] * d[1]) / (d[0] * d[0] + d[1] * d[1])).clamp(0.0, 1.0);
    ((w[0] - s * d[0]).powi(2) + (w[1] - s * d[1]).powi(2)).sqrt()
}

/// The values of the outputs at T from the last step.
pub fn values(o: &Outputs, p: &Problem, last: &StepResult) -> Vec<f64> {
    let contact = &p.space.contact;
    let mut v = Vec::new();
    if o.max_slip {
        v.push(last.slip.iter().fold(0.0f64, |m, s| m.max(s.abs())));
    }
    if o.stick_length {
        v.push(contact.iter().zip(&last.state).filter(|(_, s)| **s == EdgeState::Stick).map(|(c, _)| c.length).sum());
    }
    if o.contact_length {
        v.push(last.contact_lengths(&p.space).map_or(f64::NAN, |l| l[0]));
    }
    if o.max_pressure {
        let p = last.normal.force.iter().zip(contact).map(|(f, c)| f / c.length);
        v.push(if last.normal.force.is_empty() { f64::NAN } else { p.fold(f64::NEG_INFINITY, f64::max) });
    }
    if o.elastic_energy {
        v.push(0.5 * last.energy);
    }
    for &x in &o.traction_at {
        let near = contact.iter().enumerate().min_by(|(_, a), (_, b)| {
            let d = |c: &crate::fem::space::ContactEdge| {
                let [i, j] = p.mesh.edges[c.edge];
                segment_distance(x, p.mesh.points[i], p.mesh.points[j])
            };
            d(a).total_cmp(&d(b))
        });
        v.push(near.map_or(f64::NAN, |(k, c)| -last.mu[k] / c.length));
    }
    v
}

/// The estimate of one output over the levels.
#[derive(Clone, Debug)]
pub struct OutputEstimate {
    pub name: String,
    /// Order and extrapolated value of the three finest levels, if they converge monotonically.
    pub model: Option<ScalarModel>,
    /// Per level: estimated error |Q_l − Q*|, GCI, verdict.
    pub levels: Vec<(f64, f64, Verdict)>,
}

/// Estimates of every output from sizes x (h or k, named by `size`; coarse → fine) and values q[level][output].
pub fn estimate(names: &[String], size: Axis, x: &[f64], q: &[Vec<f64>]) -> Vec<OutputEstimate> {
    let n = x.len();
    names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let v: Vec<f64> = q.iter().map(|r| r[i]).collect();
            let p_th = theoretical_order(name, size);
            let nan = |why: &str| vec![(f64::NAN, f64::NAN, Verdict::NotYet(why.to_string())); n];
            if n == 2 {
                // two levels: p = p_th assumed, F_s = 3, never called asymptotic
                let r = x[0] / x[1];
                let e1 = (v[1] - v[0]).abs() / (r.powf(p_th) - 1.0);
                let why = Verdict::NotYet("two levels: the order is assumed, not observed".into());
                let levels = vec![(e1 * r.powf(p_th), FS_TWO * e1 * r.powf(p_th), why.clone()), (e1, FS_TWO * e1, why)];
                return OutputEstimate { name: name.clone(), model: None, levels };
            }
            if n < 2 {
                return OutputEstimate { name: name.clone(), model: None, levels: nan("one level") };
            }
            let (xs, qs) = ([x[n - 3], x[n - 2], x[n - 1]], [v[n - 3], v[n - 2], v[n - 1]]);
            let Some(m) = ScalarModel::fit(xs, qs) else {
                let scale = qs.iter().fold(0.0f64, |m, q| m.max(q.abs()));
                let why = if (qs[2] - qs[1]).abs() <= 1e-12 * scale {
                    "the two finest values agree to rounding"
                } else if (qs[2] - qs[1]) * (qs[1] - qs[0]) < 0.0 {
                    "the three finest values oscillate"
                } else {
                    "no order in (0, 8] fits the three finest values"
                };
                return OutputEstimate { name: name.clone(), model: None, levels: nan(why) };
            };
            let est: Vec<f64> = v.iter().map(|q| (q - m.limit).abs()).collect();
            let verdicts = asymptotic(x, m.p, &est, p_th);
            let levels = est.iter().zip(verdicts).map(|(&e, vd)| (e, FS_THREE * e, vd)).collect();
            OutputEstimate { name: name.clone(), model: Some(m), levels }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Q = 0.05 − 0.02 h (order 1, the theoretical one) on four levels is extrapolated to 0.05 and in range;
    /// the energy column with Q = 1 + h^2.5 (above its theoretical order 2 + 0.15) is refused; an
    /// oscillating column is refused with that reason.
    #[test]
    fn outputs_extrapolate_and_refuse() {
        let x: [f64; 4] = [0.4, 0.2, 0.1, 0.05];
        let names: Vec<String> = ["max_slip", "elastic_energy", "stick_length"].map(String::from).to_vec();
        let q: Vec<Vec<f64>> = x
            .iter()
            .enumerate()
            .map(|(i, h)| vec![0.05 - 0.02 * h, 1.0 + h.powf(2.5), 0.5 + 0.1 * (-1f64).powi(i as i32) * h])
            .collect();
        let e = estimate(&names, Axis::H, &x, &q);
        let m = e[0].model.unwrap();
        assert!((m.limit - 0.05).abs() < 1e-12 && (m.p - 1.0).abs() < 1e-9);
        assert!(e[0].levels.iter().all(|l| l.2 == Verdict::InRange && (l.0 - 0.0).abs() < 0.0081));
        assert!((e[0].levels[3].0 - 0.001).abs() < 1e-12 && (e[0].levels[3].1 - 0.00125).abs() < 1e-12);
        assert!(e[1].levels.iter().all(|l| l.2.text().contains("outside")));
        assert!(e[2].model.is_none() && e[2].levels[0].2.text().contains("oscillate"));
    }
}
