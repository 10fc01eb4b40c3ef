//! Properties of the field that must hold everywhere, and an independent check of the whole
//! chain (coordinates, Legendre functions, sums, rotation, signs) against the potential.

use core::f64::consts::{FRAC_PI_2, PI};

use proptest::prelude::*;
use truenorth_core::{Error, MagneticHeading, angle_diff};
use truenorth_geomag::{
    Extrapolation, GEOMAGNETIC_REFERENCE_RADIUS_M, Geodetic, MAX_DEGREE, MagneticField,
    PreparedPoint, SchmidtLegendre, WGS84_ECCENTRICITY_SQUARED, WGS84_SEMI_MAJOR_AXIS_M, WMM2025,
    WorldMagneticModel, declination, field_at, field_at_deg, inclination_rad, total_intensity_nt,
};

fn field(lat: f64, lon: f64, h: f64, year: f64) -> MagneticField {
    field_at(lat, lon, h, year).expect("valid input")
}

/// Largest change of X, Y or Z between two results, nT.
fn jump(a: &MagneticField, b: &MagneticField) -> f64 {
    (a.x_nt - b.x_nt)
        .abs()
        .max((a.y_nt - b.y_nt).abs())
        .max((a.z_nt - b.z_nt).abs())
}

/// Steps of 1e-6 rad (≈ 6 m on the ground). The field's gradient is below ~2·10⁵ nT per
/// radian (a few times F), so a continuous field moves less than 1 nT per step; a sign
/// slip, a wrapped longitude or a pole singularity jumps by hundreds to thousands of nT.
const STEP_RAD: f64 = 1e-6;
const MAX_JUMP_NT: f64 = 1.0;

fn all_finite(f: &MagneticField) -> bool {
    let sv = f.secular_variation;
    [
        f.x_nt,
        f.y_nt,
        f.z_nt,
        f.h_nt,
        f.f_nt,
        f.inclination_rad,
        f.declination_rad,
        f.grid_variation_rad.unwrap_or(0.0),
        sv.x_nt_per_yr,
        sv.y_nt_per_yr,
        sv.z_nt_per_yr,
        sv.h_nt_per_yr,
        sv.f_nt_per_yr,
        sv.inclination_rad_per_yr,
        sv.declination_rad_per_yr,
    ]
    .iter()
    .all(|v| v.is_finite())
}

/// The scalar potential V (WMM2025 Technical Report, eq. 1), nT·m, built only from public
/// pieces: the coordinate conversion, the Legendre functions and the coefficients.
fn potential(lat: f64, lon: f64, h: f64, year: f64) -> f64 {
    let sph = Geodetic::new(lat, lon, h).unwrap().to_spherical();
    let leg = SchmidtLegendre::new(sph.sin_lat(), sph.cos_lat());
    let a = GEOMAGNETIC_REFERENCE_RADIUS_M;
    let dt = year - WMM2025.epoch_year();
    let mut v = 0.0;
    for n in 1..=MAX_DEGREE {
        let mut s = 0.0;
        for m in 0..=n {
            let t = WMM2025.term(n, m).unwrap();
            let g = t.g_nt + dt * t.g_sv_nt_per_yr;
            let hh = t.h_nt + dt * t.h_sv_nt_per_yr;
            let ml = m as f64 * lon;
            s += (g * ml.cos() + hh * ml.sin()) * leg.p(n, m).unwrap();
        }
        v += (a / sph.radius_m()).powi(n as i32 + 1) * s;
    }
    a * v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// The elements are consistent with the vector: H = √(X²+Y²), F = √(H²+Z²),
    /// D = atan2(Y, X), I = atan2(Z, H).
    #[test]
    fn elements_follow_from_the_vector(
        lat in -FRAC_PI_2..=FRAC_PI_2,
        lon in -2.0 * PI..2.0 * PI,
        h in -1_000.0f64..850_000.0,
        year in 2025.0f64..=2030.0,
    ) {
        let f = field(lat, lon, h, year);
        prop_assert!(all_finite(&f));
        let rel = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        prop_assert!(rel(f.h_nt, (f.x_nt.powi(2) + f.y_nt.powi(2)).sqrt()));
        prop_assert!(rel(f.f_nt, (f.h_nt.powi(2) + f.z_nt.powi(2)).sqrt()));
        prop_assert!(angle_diff(f.declination_rad, f.y_nt.atan2(f.x_nt)).abs() < 1e-12);
        prop_assert!(angle_diff(f.inclination_rad, f.z_nt.atan2(f.h_nt)).abs() < 1e-12);
        // The Earth's field is between ~20 000 and ~70 000 nT at the surface and weakens
        // upwards; it is never zero.
        prop_assert!(f.f_nt > 15_000.0 && f.f_nt < 70_000.0, "F = {}", f.f_nt);
    }

    /// Continuity in latitude along any meridian, up to and including both poles.
    #[test]
    fn continuous_in_latitude(
        lat in -FRAC_PI_2..=(FRAC_PI_2 - STEP_RAD),
        lon in -PI..=PI,
        year in 2025.0f64..=2030.0,
    ) {
        let a = field(lat, lon, 0.0, year);
        let b = field(lat + STEP_RAD, lon, 0.0, year);
        prop_assert!(jump(&a, &b) < MAX_JUMP_NT, "jump {} nT at lat {}", jump(&a, &b), lat);
    }

    /// Continuity in longitude everywhere, across the date line (λ crossing ±π) and near
    /// the poles, where the meridians converge.
    #[test]
    fn continuous_in_longitude(
        lat in -FRAC_PI_2..=FRAC_PI_2,
        lon in -PI - 0.01..=PI + 0.01,
        year in 2025.0f64..=2030.0,
    ) {
        let a = field(lat, lon, 0.0, year);
        let b = field(lat, lon + STEP_RAD, 0.0, year);
        prop_assert!(jump(&a, &b) < MAX_JUMP_NT, "jump {} nT at lon {}", jump(&a, &b), lon);
    }

    /// Near the poles (within 0.1°), in both directions of approach.
    #[test]
    fn continuous_near_the_poles(
        below in 0.0f64..0.0017,
        lon in -PI..=PI,
        north: bool,
    ) {
        let sign = if north { 1.0 } else { -1.0 };
        let a = field(sign * (FRAC_PI_2 - below), lon, 0.0, 2027.0);
        let b = field(sign * (FRAC_PI_2 - below - STEP_RAD), lon, 0.0, 2027.0);
        prop_assert!(all_finite(&a));
        prop_assert!(jump(&a, &b) < MAX_JUMP_NT);
        prop_assert!(a.grid_variation_rad.is_some());
    }

    /// The main field is linear in time with the secular variation as its slope.
    #[test]
    fn secular_variation_is_the_time_slope(
        lat in -1.5f64..1.5,
        lon in -PI..=PI,
    ) {
        let a = field(lat, lon, 0.0, 2025.0);
        let b = field(lat, lon, 0.0, 2030.0);
        let sv = a.secular_variation;
        prop_assert!((b.x_nt - a.x_nt - 5.0 * sv.x_nt_per_yr).abs() < 1e-6);
        prop_assert!((b.y_nt - a.y_nt - 5.0 * sv.y_nt_per_yr).abs() < 1e-6);
        prop_assert!((b.z_nt - a.z_nt - 5.0 * sv.z_nt_per_yr).abs() < 1e-6);
        // The element rates are the derivatives of the elements (central difference).
        let d = 1e-3;
        let (m, p) = (field(lat, lon, 0.0, 2027.5 - d), field(lat, lon, 0.0, 2027.5 + d));
        let mid = field(lat, lon, 0.0, 2027.5).secular_variation;
        prop_assert!(((p.f_nt - m.f_nt) / (2.0 * d) - mid.f_nt_per_yr).abs() < 1e-4);
        prop_assert!(((p.h_nt - m.h_nt) / (2.0 * d) - mid.h_nt_per_yr).abs() < 1e-4);
        prop_assert!((angle_diff(p.inclination_rad, m.inclination_rad) / (2.0 * d)
            - mid.inclination_rad_per_yr).abs() < 1e-8);
        prop_assert!((angle_diff(p.declination_rad, m.declination_rad) / (2.0 * d)
            - mid.declination_rad_per_yr).abs() < 1e-6);
    }

    /// X, Y, Z are minus the gradient of the potential in the local geodetic frame:
    /// X = −∂V/∂φ / (M + h), Y = −∂V/∂λ / ((N + h) cos φ), Z = ∂V/∂h, with M and N the
    /// meridian and prime-vertical radii of curvature of WGS84. An independent check of
    /// the Legendre derivatives, the geocentric conversion, the rotation and every sign.
    #[test]
    fn field_is_minus_the_gradient_of_the_potential(
        lat in -1.5f64..1.5,
        lon in -PI..=PI,
        h in 0.0f64..500_000.0,
        year in 2025.0f64..=2030.0,
    ) {
        let f = field(lat, lon, h, year);
        let e2 = WGS84_ECCENTRICITY_SQUARED;
        let w = (1.0 - e2 * lat.sin().powi(2)).sqrt();
        let n_radius = WGS84_SEMI_MAJOR_AXIS_M / w;
        let m_radius = WGS84_SEMI_MAJOR_AXIS_M * (1.0 - e2) / w.powi(3);
        let (da, dh) = (1e-5, 10.0);
        let dv_dlat = (potential(lat + da, lon, h, year) - potential(lat - da, lon, h, year)) / (2.0 * da);
        let dv_dlon = (potential(lat, lon + da, h, year) - potential(lat, lon - da, h, year)) / (2.0 * da);
        let dv_dh = (potential(lat, lon, h + dh, year) - potential(lat, lon, h - dh, year)) / (2.0 * dh);
        let x = -dv_dlat / (m_radius + h);
        let y = -dv_dlon / ((n_radius + h) * lat.cos());
        let z = dv_dh;
        prop_assert!((x - f.x_nt).abs() < 1e-3, "X {} vs {}", x, f.x_nt);
        prop_assert!((y - f.y_nt).abs() < 1e-3, "Y {} vs {}", y, f.y_nt);
        prop_assert!((z - f.z_nt).abs() < 1e-3, "Z {} vs {}", z, f.z_nt);
    }

    /// Any f64 at all gives a typed error or a finite result; never a panic.
    #[test]
    fn any_f64_never_panics(lat: f64, lon: f64, h: f64, year: f64) {
        for model in [
            WorldMagneticModel::WMM2025,
            WorldMagneticModel::WMM2025.with_extrapolation(Extrapolation::Allow),
        ] {
            for r in [model.field_at(lat, lon, h, year), model.field_at_deg(lat, lon, h, year)] {
                match r {
                    Ok(f) => prop_assert!(all_finite(&f)),
                    Err(Error::NonFinite { .. } | Error::OutOfRange { .. } | Error::DateOutOfRange { .. }) => {}
                    Err(e) => prop_assert!(false, "unexpected error {e:?}"),
                }
            }
        }
    }

    /// Special values in every position, mixed with plausible ones.
    #[test]
    fn special_values_never_panic(
        lat in prop::sample::select(vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -0.0, 90.0, -90.0, 1.0, f64::MAX, f64::MIN_POSITIVE]),
        lon in prop::sample::select(vec![f64::NAN, f64::INFINITY, 0.0, 180.0, -180.0, 1e300, -1e-300]),
        h in prop::sample::select(vec![f64::NAN, f64::NEG_INFINITY, 0.0, -1000.0, 1e7, 1e300]),
        year in prop::sample::select(vec![f64::NAN, f64::INFINITY, 2025.0, 2030.0, 2031.0, -1e300, 2130.1]),
    ) {
        let allow = WorldMagneticModel::WMM2025.with_extrapolation(Extrapolation::Allow);
        if let Ok(f) = allow.field_at_deg(lat, lon, h, year) {
            prop_assert!(all_finite(&f));
        }
        if let Ok(f) = field_at(lat, lon, h, year) {
            prop_assert!(all_finite(&f));
        }
    }

    /// A prepared point gives bit-identical results to a direct evaluation.
    #[test]
    fn prepared_point_equals_direct(
        lat in -FRAC_PI_2..=FRAC_PI_2,
        lon in -PI..=PI,
        year in 2025.0f64..=2030.0,
    ) {
        let at = Geodetic::new(lat, lon, 1000.0).unwrap();
        let p = PreparedPoint::new(&at);
        let m = WorldMagneticModel::WMM2025;
        prop_assert_eq!(m.field_prepared(&p, year).unwrap(), m.field(&at, year).unwrap());
    }
}

#[test]
fn date_line_is_one_meridian() {
    for lat in [-89.0, -60.0, 0.0, 45.0, 89.9] {
        let a = field_at_deg(lat, 180.0, 0.0, 2026.0).unwrap();
        let b = field_at_deg(lat, -180.0, 0.0, 2026.0).unwrap();
        assert_eq!(a, b, "lat {lat}");
        let c = field_at_deg(lat, 179.999_999, 0.0, 2026.0).unwrap();
        let d = field_at_deg(lat, -179.999_999, 0.0, 2026.0).unwrap();
        assert!(jump(&c, &d) < MAX_JUMP_NT, "lat {lat}: {}", jump(&c, &d));
    }
}

/// At the geographic poles the field is finite; along a meridian it meets the value just
/// off the pole, and all meridians agree on the field vector up to the rotation of the
/// local frame (so F, Z and I do not depend on the longitude there).
#[test]
fn the_poles_are_regular() {
    for lat in [90.0, -90.0] {
        let mut first: Option<MagneticField> = None;
        for lon in [-180.0, -90.0, 0.0, 33.3, 90.0, 180.0] {
            let f = field_at_deg(lat, lon, 0.0, 2025.0).unwrap();
            assert!(all_finite(&f), "{lat} {lon}");
            if let Some(g) = first {
                assert!((f.f_nt - g.f_nt).abs() < 1e-6);
                assert!((f.z_nt - g.z_nt).abs() < 1e-6);
                assert!((f.h_nt - g.h_nt).abs() < 1e-6);
            }
            first = Some(f);
        }
    }
}

#[test]
fn dates_outside_the_model_are_refused_unless_opted_in() {
    let refuse = field_at_deg(45.0, 7.0, 0.0, 2030.5);
    assert!(matches!(
        refuse,
        Err(Error::DateOutOfRange {
            year: 2030.5,
            valid_from: 2025.0,
            valid_to: 2030.0
        })
    ));
    assert!(matches!(
        field_at_deg(45.0, 7.0, 0.0, 2024.9),
        Err(Error::DateOutOfRange { .. })
    ));
    let allow = WorldMagneticModel::WMM2025.with_extrapolation(Extrapolation::Allow);
    let f = allow.field_at_deg(45.0, 7.0, 0.0, 2030.5).unwrap();
    let w = f
        .extrapolated
        .expect("an extrapolated result carries the warning");
    assert_eq!((w.year, w.valid_from, w.valid_to), (2030.5, 2025.0, 2030.0));
    assert!(
        allow
            .field_at_deg(45.0, 7.0, 0.0, 2029.0)
            .unwrap()
            .extrapolated
            .is_none()
    );
}

#[test]
fn invalid_positions_are_typed_errors() {
    assert!(matches!(
        field_at_deg(90.01, 0.0, 0.0, 2026.0),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        field_at_deg(-91.0, 0.0, 0.0, 2026.0),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        field_at_deg(f64::NAN, 0.0, 0.0, 2026.0),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        field_at_deg(0.0, f64::INFINITY, 0.0, 2026.0),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        field_at_deg(0.0, 0.0, f64::NAN, 2026.0),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        field_at_deg(0.0, 0.0, 0.0, f64::NAN),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        field_at(1.6, 0.0, 0.0, 2026.0),
        Err(Error::OutOfRange { .. })
    ));
}

/// Declination through the helper equals the field's, and turns magnetic into true heading
/// through core's type exactly once.
#[test]
fn declination_helper_and_true_heading() {
    let (lat, lon) = (0.0_f64, 120f64.to_radians());
    let d = declination(lat, lon, 0.0, 2025.0).unwrap();
    let f = field(lat, lon, 0.0, 2025.0);
    assert_eq!(d, f.declination());
    // Test value: 0° N 120° E, 2025.0 → D = −0.16°.
    assert!((d.0.to_degrees() + 0.16).abs() < 0.01);
    assert_eq!(total_intensity_nt(lat, lon, 0.0, 2025.0).unwrap(), f.f_nt);
    assert_eq!(
        inclination_rad(lat, lon, 0.0, 2025.0).unwrap(),
        f.inclination_rad
    );
    assert!(total_intensity_nt(lat, lon, 0.0, 2035.0).is_err());
    let t = MagneticHeading::new(0.5).to_true(d);
    assert!(angle_diff(t.rad(), 0.5 + d.0).abs() < 1e-12);
}

/// The grid variation exists only poleward of 55° and equals D ∓ λ there.
#[test]
fn grid_variation_only_in_polar_regions() {
    assert!(
        field_at_deg(54.9, 10.0, 0.0, 2026.0)
            .unwrap()
            .grid_variation_rad
            .is_none()
    );
    assert!(
        field_at_deg(-54.9, 10.0, 0.0, 2026.0)
            .unwrap()
            .grid_variation_rad
            .is_none()
    );
    let n = field_at_deg(70.0, 10.0, 0.0, 2026.0).unwrap();
    assert!((n.grid_variation_deg().unwrap() - (n.declination_deg() - 10.0)).abs() < 1e-9);
    let s = field_at_deg(-70.0, 10.0, 0.0, 2026.0).unwrap();
    assert!((s.grid_variation_deg().unwrap() - (s.declination_deg() + 10.0)).abs() < 1e-9);
}
