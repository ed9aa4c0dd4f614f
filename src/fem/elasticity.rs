//! The one constitutive law: isotropic linear elasticity in plane strain.
//!
//! With Lamé's λ = Eν/((1+ν)(1−2ν)) and μ = E/(2(1+ν)), for a displacement gradient G = ∇u (G[c][d] =
//! ∂u_c/∂x_d, constant on a CR triangle) and ε = ½(G + Gᵀ):
//!   σ = λ tr ε I + 2μ ε   (σ_zz = λ tr ε, ε_zz = 0),
//!   σ:ε = λ (tr ε)² + 2μ ε:ε   (the energy density of a_h's volume term),
//!   σ_vM = √(½[(σxx−σyy)² + (σyy−σzz)² + (σzz−σxx)²] + 3σxy²).
//! Every use of the law in the crate (element stiffness, true errors, study differences, output fields)
//! goes through [`Elasticity`].

use crate::scene::Material;

/// The law of one material: Lamé's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Elasticity {
    pub lam: f64,
    pub mu: f64,
}

/// Plane-strain strain and stress of a constant gradient: (xx, yy, xy) of ε (tensor shear) and
/// (xx, yy, zz, xy) of σ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrainStress {
    pub strain: [f64; 3],
    pub stress: [f64; 4],
}

impl Elasticity {
    pub fn new(m: &Material) -> Elasticity {
        Elasticity { lam: m.e * m.nu / ((1.0 + m.nu) * (1.0 - 2.0 * m.nu)), mu: m.e / (2.0 * (1.0 + m.nu)) }
    }

    /// Element stiffness block of basis functions with constant gradients gi, gj on a triangle of area
    /// `area`: [c][d] = ∫_T σ(φ_j e_d):ε(φ_i e_c).
    pub fn element_block(&self, area: f64, gi: [f64; 2], gj: [f64; 2]) -> [[f64; 2]; 2] {
        let (lam, mu) = (self.lam, self.mu);
        let dot = gi[0] * gj[0] + gi[1] * gj[1];
        let mut b = [[0.0; 2]; 2];
        for c in 0..2 {
            for d in 0..2 {
                let delta = if c == d { dot } else { 0.0 };
                b[c][d] = area * (lam * gi[c] * gj[d] + mu * (delta + gi[d] * gj[c]));
            }
        }
        b
    }

    /// σ(G):ε(G) for a constant displacement gradient G.
    pub fn energy_density(&self, g: [[f64; 2]; 2]) -> f64 {
        let e01 = 0.5 * (g[0][1] + g[1][0]);
        let tr = g[0][0] + g[1][1];
        self.lam * tr * tr + 2.0 * self.mu * (g[0][0] * g[0][0] + 2.0 * e01 * e01 + g[1][1] * g[1][1])
    }

    /// ε and σ of a constant displacement gradient G.
    pub fn strain_stress(&self, g: [[f64; 2]; 2]) -> StrainStress {
        let (lam, mu) = (self.lam, self.mu);
        let (exx, eyy, exy) = (g[0][0], g[1][1], 0.5 * (g[0][1] + g[1][0]));
        let tr = exx + eyy;
        StrainStress {
            strain: [exx, eyy, exy],
            stress: [lam * tr + 2.0 * mu * exx, lam * tr + 2.0 * mu * eyy, lam * tr, 2.0 * mu * exy],
        }
    }
}

/// Von Mises equivalent stress of (σxx, σyy, σzz, σxy).
pub fn von_mises([sxx, syy, szz, sxy]: [f64; 4]) -> f64 {
    (0.5 * ((sxx - syy).powi(2) + (syy - szz).powi(2) + (szz - sxx).powi(2)) + 3.0 * sxy * sxy).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The energy density is σ:ε, and the element block is its bilinear form: Gᵢᵀ-weighted sums of the
    /// block reproduce the density of a sum of basis gradients (area 1).
    #[test]
    fn energy_density_is_stress_double_dot_strain_and_matches_the_element_block() {
        let law = Elasticity::new(&Material { e: 3.0, nu: 0.3 });
        let g = [[0.7, -1.3], [0.4, 2.1]];
        let ss = law.strain_stress(g);
        let [exx, eyy, exy] = ss.strain;
        let [sxx, syy, _, sxy] = ss.stress;
        let dd = sxx * exx + syy * eyy + 2.0 * sxy * exy;
        assert!((law.energy_density(g) - dd).abs() <= 1e-13 * dd.abs());
        // u = e_0 x-gradient gi in component 0 plus gj in component 1: G = [gi; gj]
        let (gi, gj) = ([0.7, -1.3], [0.4, 2.1]);
        let b00 = law.element_block(1.0, gi, gi)[0][0];
        let b11 = law.element_block(1.0, gj, gj)[1][1];
        let b01 = law.element_block(1.0, gi, gj)[0][1];
        let quad = b00 + b11 + 2.0 * b01;
        assert!((quad - dd).abs() <= 1e-13 * dd.abs(), "{quad} vs {dd}");
    }

    /// Lamé's parameters of E = 1, ν = 0.25 are λ = μ = 0.4; von Mises of a pure shear σxy = s is √3 s.
    #[test]
    fn lame_parameters_and_von_mises_of_pure_shear() {
        let law = Elasticity::new(&Material { e: 1.0, nu: 0.25 });
        assert!((law.lam - 0.4).abs() < 1e-15 && (law.mu - 0.4).abs() < 1e-15);
        assert!((von_mises([0.0, 0.0, 0.0, 2.0]) - 2.0 * 3f64.sqrt()).abs() < 1e-15);
    }
}
