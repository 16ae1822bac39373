/* hypo.c: the hypoplastic rate law of the slab (see hypo.h). */
#include "hypo.h"

#include <math.h>

double ekm_hypo_density_factor(const ekm_material *m, double phi)
{
    if (m->alpha == 0.0)
        return 1.0;
    if (!(phi > m->phi_co))
        return 0.0;
    return pow((phi - m->phi_co) / (m->phi_cp - phi), m->alpha);
}

double ekm_hypo_R(const ekm_material *m, ekm_variant v, double phi)
{
    const double c = v == EKM_VARIANT_THESIS ? m->zeta0 : 4.0 / 3.0 * m->eta0 + m->zeta0;
    return sqrt(3.0 * m->eps0 * c / (2.0 * phi));
}

static double norm_plane(const ekm_material *m, const ekm_hypo_plane_rate *r)
{
    const double tr = r->exx + r->ezz;
    const double dxx = r->exx - tr / 3.0, dzz = r->ezz - tr / 3.0, dyy = -tr / 3.0;
    const double gdot2 = dxx * dxx + dyy * dyy + dzz * dzz + 0.5 * r->gxz * r->gxz; /* kappa^D : kappa^D */
    return sqrt(gdot2 + m->zeta0 / (2.0 * m->eta0) * tr * tr);
}

static double norm_full(const ekm_material *m, double du_dz, double dw_dz)
{
    const ekm_hypo_plane_rate r = {0.0, dw_dz, du_dz};
    return norm_plane(m, &r);
}

double ekm_hypo_rate_norm_plane(const ekm_material *m, const ekm_hypo_plane_rate *r)
{
    return norm_plane(m, r);
}

double ekm_hypo_rate_norm(const ekm_material *m, ekm_variant v, double du_dz, double dw_dz)
{
    return v == EKM_VARIANT_THESIS ? fabs(dw_dz) : norm_full(m, du_dz, dw_dz);
}

static double coeff_a1(const ekm_material *m, double phi)
{
    return 2.0 / (9.0 * m->zeta0) * sqrt(phi * m->eta0 / (3.0 * m->eps0));
}

static double coeff_a2(const ekm_material *m, double phi)
{
    return sqrt(phi / (3.0 * m->eta0 * m->eps0));
}

ekm_hypo_stress ekm_hypo_rate_plane(const ekm_material *m, ekm_variant v, double phi,
                                    const ekm_hypo_stress *s, const ekm_hypo_plane_rate *r, double knorm,
                                    double ktr)
{
    const double A = m->A_h, B = m->B_h;
    const double f = ekm_hypo_density_factor(m, phi);
    const double PY = ekm_pressure_yield(m, phi);
    const double tr = r->exx + r->ezz;
    ekm_hypo_stress d = {0};
    if (!(PY > 0.0)) { /* loose (phi <= phi_co): no limit surface, elastic */
        d.xz = f * B * r->gxz;
        d.zz = f * (v == EKM_VARIANT_THESIS ? A * tr : A * tr + 2.0 * B * r->ezz);
        d.xx = v == EKM_VARIANT_THESIS ? d.zz : f * (A * tr + 2.0 * B * r->exx);
        d.yy = v == EKM_VARIANT_THESIS ? d.zz : f * A * tr;
        return d;
    }
    const double a2 = coeff_a2(m, phi);
    /* Shear: the deviatoric part of the full law in both variants. */
    d.xz = f * (B * r->gxz - 2.0 * B * a2 * s->xz / PY * knorm);
    if (v == EKM_VARIANT_THESIS) {
        const double R = ekm_hypo_R(m, v, phi);
        d.zz = f * A * (tr - (s->zz + PY) / (R * PY) * ktr);
        d.xx = d.yy = d.zz;
        return d;
    }
    const double a1 = coeff_a1(m, phi);
    const double trs = s->xx + s->yy + s->zz;
    const double q = (trs + 3.0 * PY) / PY;
    const double Niso = (3.0 * A + 2.0 * B) * a1 * q;
    const double dev = 2.0 * B * a2 / PY;
    d.xx = f * (A * tr + 2.0 * B * r->exx - (Niso + dev * (s->xx - trs / 3.0)) * knorm);
    d.yy = f * (A * tr - (Niso + dev * (s->yy - trs / 3.0)) * knorm);
    d.zz = f * (A * tr + 2.0 * B * r->ezz - (Niso + dev * (s->zz - trs / 3.0)) * knorm);
    return d;
}

ekm_hypo_stress ekm_hypo_rate_plane_magnitude(const ekm_material *m, ekm_variant v, double phi,
                                              const ekm_hypo_stress *s, const ekm_hypo_plane_rate *r,
                                              double knorm, double ktr)
{
    const double A = m->A_h, B = m->B_h;
    const double f = ekm_hypo_density_factor(m, phi);
    const double PY = ekm_pressure_yield(m, phi);
    const double tr = fabs(r->exx) + fabs(r->ezz); /* |A tr| with the rates' own magnitudes */
    const double exx = fabs(r->exx), ezz = fabs(r->ezz), gxz = fabs(r->gxz);
    ekm_hypo_stress d = {0};
    if (!(PY > 0.0)) {
        d.xz = f * B * gxz;
        d.zz = f * (v == EKM_VARIANT_THESIS ? A * tr : A * tr + 2.0 * B * ezz);
        d.xx = v == EKM_VARIANT_THESIS ? d.zz : f * (A * tr + 2.0 * B * exx);
        d.yy = v == EKM_VARIANT_THESIS ? d.zz : f * A * tr;
        return d;
    }
    const double a2 = coeff_a2(m, phi);
    d.xz = f * (B * gxz + 2.0 * B * a2 * fabs(s->xz) / PY * knorm);
    if (v == EKM_VARIANT_THESIS) {
        const double R = ekm_hypo_R(m, v, phi);
        d.zz = f * A * (tr + fabs(s->zz + PY) / (R * PY) * ktr);
        d.xx = d.yy = d.zz;
        return d;
    }
    const double a1 = coeff_a1(m, phi);
    const double trs = s->xx + s->yy + s->zz;
    const double Niso = (3.0 * A + 2.0 * B) * a1 * (fabs(trs) + 3.0 * PY) / PY;
    const double dev = 2.0 * B * a2 / PY;
    d.xx = f * (A * tr + 2.0 * B * exx + (Niso + dev * fabs(s->xx - trs / 3.0)) * knorm);
    d.yy = f * (A * tr + (Niso + dev * fabs(s->yy - trs / 3.0)) * knorm);
    d.zz = f * (A * tr + 2.0 * B * ezz + (Niso + dev * fabs(s->zz - trs / 3.0)) * knorm);
    return d;
}

ekm_hypo_stress ekm_hypo_rate(const ekm_material *m, ekm_variant v, double phi, const ekm_hypo_stress *s,
                              double du_dz, double dw_dz)
{
    const ekm_hypo_plane_rate r = {0.0, dw_dz, du_dz};
    return ekm_hypo_rate_plane(m, v, phi, s, &r, norm_plane(m, &r), fabs(dw_dz));
}

double ekm_hypo_yield(const ekm_material *m, ekm_variant v, double phi, const ekm_hypo_stress *s)
{
    const double PY = ekm_pressure_yield(m, phi);
    if (!(PY > 0.0))
        return INFINITY;
    if (v == EKM_VARIANT_THESIS) {
        const double q = (s->zz + PY) / (ekm_hypo_R(m, v, phi) * PY);
        return q * q - 1.0;
    }
    const double tr = s->xx + s->yy + s->zz;
    const double dxx = s->xx - tr / 3.0, dyy = s->yy - tr / 3.0, dzz = s->zz - tr / 3.0;
    const double s2 = dxx * dxx + dyy * dyy + dzz * dzz + 2.0 * s->xz * s->xz;
    const double q = tr + 3.0 * PY;
    return (q * q + 9.0 * m->zeta0 / (2.0 * m->eta0) * s2) /
               (27.0 * m->zeta0 * m->eps0 / (2.0 * phi) * PY * PY) -
           1.0;
}

ekm_hypo_stress ekm_hypo_from_flow(const ekm_material *m, ekm_variant v, double phi, double T, double du_dz,
                                   double dw_dz)
{
    const ekm_transport c = ekm_transport_coefficients(m, v, phi, T);
    const double P = ekm_pressure_kinetic(m, phi, T) + ekm_pressure_yield(m, phi);
    ekm_hypo_stress s;
    s.zz = -P + c.mu_n * dw_dz;
    s.xz = c.eta * du_dz;
    if (v == EKM_VARIANT_THESIS)
        s.xx = s.yy = s.zz;
    else
        s.xx = s.yy = -P + (c.zeta - 2.0 / 3.0 * c.eta) * dw_dz;
    return s;
}

double ekm_hypo_flow_T_for_stress(const ekm_material *m, ekm_variant v, double phi, double dw_dz,
                                  double sigma_zz)
{
    if (phi > m->phi_co || !(phi > 0.0))
        return -1.0;
    const double P0 = ekm_pressure_kinetic(m, phi, 1.0);
    const double b = ekm_transport_coefficients(m, v, phi, 1.0).mu_n * dw_dz;
    /* P0 x^2 - b x + sigma_zz = 0, x = sqrt(T) */
    const double disc = b * b - 4.0 * P0 * sigma_zz;
    if (!(disc >= 0.0) || !(P0 > 0.0))
        return -1.0;
    const double x = (b + sqrt(disc)) / (2.0 * P0);
    return x >= 0.0 ? x * x : -1.0;
}

double ekm_hypo_relaxation_rate_plane(const ekm_material *m, ekm_variant v, double phi,
                                      const ekm_hypo_plane_rate *r)
{
    const double PY = ekm_pressure_yield(m, phi);
    if (!(PY > 0.0))
        return 0.0;
    const double f = ekm_hypo_density_factor(m, phi), k = norm_plane(m, r);
    const double dev = f * 2.0 * m->B_h * coeff_a2(m, phi) * k / PY;
    const double vol = v == EKM_VARIANT_THESIS
                           ? f * m->A_h * fabs(r->exx + r->ezz) / (ekm_hypo_R(m, v, phi) * PY)
                           : f * 3.0 * (3.0 * m->A_h + 2.0 * m->B_h) * coeff_a1(m, phi) * k / PY;
    return dev > vol ? dev : vol;
}

double ekm_hypo_relaxation_rate(const ekm_material *m, ekm_variant v, double phi, double du_dz, double dw_dz)
{
    const ekm_hypo_plane_rate r = {0.0, dw_dz, du_dz};
    return ekm_hypo_relaxation_rate_plane(m, v, phi, &r);
}

ekm_hypo_implicit ekm_hypo_prepare_plane(const ekm_material *m, ekm_variant v, double phi, double dt,
                                         const ekm_hypo_stress *s, const ekm_hypo_plane_rate *r_old)
{
    const double A = m->A_h, B = m->B_h;
    const double PY = ekm_pressure_yield(m, phi);
    ekm_hypo_implicit c = {0};
    const int loose = !(PY > 0.0); /* no limit surface: the elastic part only */
    const double fdt = ekm_hypo_density_factor(m, phi) * dt;
    const double a2 = coeff_a2(m, phi);
    const double kfull = norm_plane(m, r_old);
    const double c_d = loose ? 0.0 : fdt * 2.0 * B * a2 * kfull / PY;
    c.xz_scale = 1.0 / (1.0 + c_d);
    c.Vxz = fdt * B / (1.0 + c_d);
    if (v == EKM_VARIANT_THESIS) {
        const double R = ekm_hypo_R(m, v, phi);
        const double cz = loose ? 0.0 : fdt * A * fabs(r_old->exx + r_old->ezz) / (R * PY);
        c.Ezz = (s->zz - cz * PY) / (1.0 + cz);
        c.Vzz = fdt * A / (1.0 + cz);
        c.Exx = c.Eyy = c.Ezz;
        c.Vxx = c.Vzz;
        return c;
    }
    const double a1 = coeff_a1(m, phi);
    const double K3 = 3.0 * A + 2.0 * B;
    const double c_p = loose ? 0.0 : fdt * 3.0 * K3 * a1 * kfull / PY;
    const double tr = s->xx + s->yy + s->zz;
    const double iso = (tr - 3.0 * c_p * PY) / (3.0 * (1.0 + c_p)); /* tr(sigma)^{n+1}/3 at zero rates */
    const double Viso = fdt * K3 / (3.0 * (1.0 + c_p));
    c.Ezz = iso + (s->zz - tr / 3.0) / (1.0 + c_d);
    c.Exx = iso + (s->xx - tr / 3.0) / (1.0 + c_d);
    c.Eyy = iso + (s->yy - tr / 3.0) / (1.0 + c_d);
    c.Vzz = Viso + fdt * 4.0 * B / (3.0 * (1.0 + c_d));
    c.Vxx = Viso - fdt * 2.0 * B / (3.0 * (1.0 + c_d));
    return c;
}

ekm_hypo_implicit ekm_hypo_prepare(const ekm_material *m, ekm_variant v, double phi, double dt,
                                   const ekm_hypo_stress *s, double du_dz_old, double dw_dz_old)
{
    const ekm_hypo_plane_rate r = {0.0, dw_dz_old, du_dz_old};
    return ekm_hypo_prepare_plane(m, v, phi, dt, s, &r);
}

ekm_hypo_stress ekm_hypo_finish_plane(const ekm_hypo_implicit *c, double sigma_xz_old,
                                      const ekm_hypo_plane_rate *r)
{
    ekm_hypo_stress s;
    s.zz = c->Ezz + c->Vzz * r->ezz + c->Vxx * r->exx;
    s.xx = c->Exx + c->Vzz * r->exx + c->Vxx * r->ezz;
    s.yy = c->Eyy + c->Vxx * (r->exx + r->ezz);
    s.xz = sigma_xz_old * c->xz_scale + c->Vxz * r->gxz;
    return s;
}

ekm_hypo_stress ekm_hypo_finish(const ekm_hypo_implicit *c, double sigma_xz_old, double du_dz, double dw_dz)
{
    ekm_hypo_stress s;
    s.zz = c->Ezz + c->Vzz * dw_dz;
    s.xx = c->Exx + c->Vxx * dw_dz;
    s.yy = c->Eyy + c->Vxx * dw_dz;
    s.xz = sigma_xz_old * c->xz_scale + c->Vxz * du_dz;
    return s;
}
