//! Real recordings (../shared/data, see its README): the least-squares fits on raw
//! magnetometer data. Each test prints what it measured. Where a recording folder is absent
//! a test prints why and skips, except under CI (`CI` set), where it fails
//! (`truenorth_sim::shared_data::folder`).
//!
//! The README quotes the figures printed here; each is asserted by [`readme_figure`].

mod recordings;

use recordings::{read_rows, readme_figure, recording, rel_std, sunsided_mag};

use nalgebra::{Matrix3, Vector2, Vector3};
use truenorth_calib::{EllipseConfig, EllipsoidConfig, fit_ellipse, fit_ellipsoid};
use truenorth_compass::CompassCalibration3d;
use truenorth_core::angle_diff;

fn full_sphere_calibration() -> Option<CompassCalibration3d> {
    // `sunsided_mag` has printed the reason when it returns `None`.
    let pts = sunsided_mag("full-sphere")?;
    Some(
        fit_ellipsoid(&pts, &EllipsoidConfig::default())
            .unwrap()
            .params,
    )
}

#[test]
fn sunsided_full_sphere_field_constancy() {
    let Some(pts) = sunsided_mag("full-sphere") else {
        return;
    };
    let before = rel_std(pts.iter().map(|p| p.norm()));
    let sol = fit_ellipsoid(&pts, &EllipsoidConfig::default()).unwrap();
    let after = rel_std(pts.iter().map(|p| sol.params.correct(p).norm()));
    println!(
        "sunsided full-sphere: {} points, |B| relative std raw {:.2} % -> calibrated {:.3} %",
        pts.len(),
        100.0 * before,
        100.0 * after
    );
    println!("  hard iron {:?}", sol.params.hard_iron.as_slice());
    println!("  soft iron {:?}", sol.params.soft_iron);
    println!("  quality {:?}", sol.quality);
    // 1 %: the spread a consumer magnetometer keeps after calibration is under it (0.46 %
    // here, 1.3 % for the unnamed tumbled sensor); the README's figure below is the binding
    // check.
    assert!(after <= 0.01, "relative std {after}");
    // The raw spread depends on the data alone: equal to the README's to its rounding.
    assert!((100.0 * before - 13.62).abs() <= 0.005, "raw {before}");
    readme_figure(
        "full-sphere |B| spread, %",
        100.0 * after,
        0.460,
        0.0005,
        pts.len(),
    );
}

/// The four single-axis turns with the 2-D fit on the two axes perpendicular to the turn.
///
/// There is no heading reference, so each 2-D calibration is checked against the 3-D
/// calibration of the `full-sphere` recording (same sensor, same session): both map the
/// readings to angles in the plane of the turn (for the 3-D one, the plane perpendicular to
/// the turn axis as the calibrated data show it, so the mount's mean tilt drops out), and
/// the RMS of their difference (less its mean) is printed. A hand-held turn wobbles; the
/// field here dips ≈ 65°, so for turns about the vertical the in-plane field is only
/// ≈ 0.21 G against ≈ 0.48 G vertical, and a 1° wobble moves the in-plane reading by
/// ≈ 2 % of it: those two recordings agree less well for reasons that are not the fit's.
#[test]
fn sunsided_single_axis_turns_2d() {
    let Some(cal3) = full_sphere_calibration() else {
        return;
    };
    // (recording, the two axes perpendicular to the rotation axis, turn axis horizontal?)
    let cases = [
        ("rotate-ccw-around-z-pointing-up", 0usize, 1usize, false),
        ("rotate-ccw-around-x-pointing-up", 1, 2, false),
        ("rotate-ccw-around-x-pointing-forward", 1, 2, true),
        ("rotate-ccw-around-y-pointing-left", 0, 2, true),
    ];
    for (rec, i, j, horizontal_axis) in cases {
        let Some(pts3) = sunsided_mag(rec) else {
            return;
        };
        let pts: Vec<_> = pts3.iter().map(|p| Vector2::new(p[i], p[j])).collect();
        let centroid = pts.iter().sum::<Vector2<f64>>() / pts.len() as f64;
        let before = rel_std(pts.iter().map(|p| (p - centroid).norm()));
        let sol = fit_ellipse(&pts, &EllipseConfig::default()).unwrap();
        let after = rel_std(pts.iter().map(|p| sol.params.correct(p).norm()));

        // The turn axis as the 3-D-calibrated data show it: the direction of least spread.
        let c3: Vec<_> = pts3.iter().map(|p| cal3.correct(p)).collect();
        let mean = c3.iter().sum::<Vector3<f64>>() / c3.len() as f64;
        let mut cov = Matrix3::zeros();
        for v in &c3 {
            cov += (v - mean) * (v - mean).transpose();
        }
        let eig = cov.symmetric_eigen();
        let mut axis: Vector3<f64> = eig.eigenvectors.column(eig.eigenvalues.imin()).into();
        if axis[3 - i - j] < 0.0 {
            axis = -axis;
        }
        let tilt_deg = axis[3 - i - j].acos().to_degrees();
        let ui = (Vector3::ith(i, 1.0) - axis * axis[i]).normalize();
        let uj = axis.cross(&ui);
        let uj = if uj[j] < 0.0 { -uj } else { uj };
        let d: Vec<f64> = c3
            .iter()
            .zip(&pts)
            .map(|(v, p)| {
                let a = sol.params.correct(p);
                angle_diff(a.y.atan2(a.x), v.dot(&uj).atan2(v.dot(&ui)))
            })
            .collect();
        let dm = d.iter().sum::<f64>() / d.len() as f64;
        let rms = (d.iter().map(|x| (x - dm).powi(2)).sum::<f64>() / d.len() as f64).sqrt();
        println!(
            "{rec}, axes ({i},{j}): {} points; radius relative std {:.1} % raw (about the centroid) -> {:.2} % calibrated; coverage {:.2}, condition {:.1}, bound {:.2}°; turn axis {:.1}° off the sensor axis; in-plane angle vs the full-sphere 3-D fit: RMS {:.2}°",
            pts.len(),
            100.0 * before,
            100.0 * after,
            sol.quality.fit.coverage,
            sol.quality.fit.condition,
            sol.quality.heading_error_bound_deg(),
            tilt_deg,
            rms.to_degrees()
        );
        assert_eq!(sol.quality.fit.coverage, 1.0);
        assert!(after < before);
        // About a horizontal axis the in-plane field is the whole 0.48 G and a degree of
        // wobble moves it by 1.7 % of itself, a degree of angle: the two calibrations agree
        // within that (the README's figures below bind tighter).
        if horizontal_axis {
            assert!(rms.to_degrees() < 1.0, "{rec}: {}", rms.to_degrees());
        }
        let quoted = match rec {
            "rotate-ccw-around-x-pointing-forward" => 0.33,
            "rotate-ccw-around-y-pointing-left" => 0.45,
            "rotate-ccw-around-x-pointing-up" => 1.07,
            _ => 5.20,
        };
        readme_figure(rec, rms.to_degrees(), quoted, 0.005, pts.len());
    }
}

/// The 347-point sample of ellipsoid_fit_python: a small fixture with strong hard iron.
#[test]
fn python_sample_fixture() {
    let Some(dir) = recording("magcal_ellipsoid_fit_python_sample") else {
        return;
    };
    let rows = read_rows(&dir.join("mag_out.txt"));
    let pts: Vec<_> = rows
        .iter()
        .map(|r| Vector3::new(r[0], r[1], r[2]))
        .collect();
    assert_eq!(pts.len(), 347);
    let sol = fit_ellipsoid(&pts, &EllipsoidConfig::default()).unwrap();
    let before = rel_std(pts.iter().map(|p| p.norm()));
    let after = rel_std(pts.iter().map(|p| sol.params.correct(p).norm()));
    let axes = truenorth_calib::fit_ellipsoid_direct(&pts)
        .unwrap()
        .semi_axes()
        .unwrap();
    println!(
        "ellipsoid_fit_python sample: |m| relative std {:.1} % -> {:.2} %; centre {:?}; field {:.1} counts; direct-fit semi-axes {:.0?}; {:?}",
        100.0 * before,
        100.0 * after,
        sol.params.hard_iron.as_slice(),
        sol.quality.field_magnitude,
        axes,
        sol.quality
    );
    // The data's README: 37 % raw, 3.5 % after its general fit; ours models the same
    // ellipsoid and may not do worse — it does better, and is held under 3 %.
    assert!(before > 0.3 && after < 0.03);
    // The README's general fit puts the centre near (−65, 80, −130) counts. With 347
    // readings at 3.5 % of a 175-count field each centre component has about
    // 0.035·175·√3/√347 = 0.6 counts of σ; 10 counts leaves room for the general fit's own
    // (unreported) error and the rounding of its quoted centre.
    assert!((sol.params.hard_iron - Vector3::new(-64.8, 79.6, -130.1)).norm() < 10.0);
}

/// CK-Explorer's tumbling log (12,000 samples), an extra real check of the 3-D fit.
#[test]
fn ck_explorer_tumble() {
    let Some(dir) = recording("magcal_ck_explorer") else {
        return;
    };
    let rows = read_rows(&dir.join("acc_mag_log.csv"));
    let pts: Vec<_> = rows
        .iter()
        .map(|r| Vector3::new(r[3], r[4], r[5]))
        .collect();
    let sol = fit_ellipsoid(&pts, &EllipsoidConfig::default()).unwrap();
    let before = rel_std(pts.iter().map(|p| p.norm()));
    let after = rel_std(pts.iter().map(|p| sol.params.correct(p).norm()));
    println!(
        "ck_explorer: {} points, |m| relative std {:.1} % -> {:.2} %; {:?}",
        pts.len(),
        100.0 * before,
        100.0 * after,
        sol.quality
    );
    // The data's README: 32 % raw, 1.3 % after an ellipsoid fit — a factor of 25; ten is the
    // least a working fit gives, and the README's figure below binds.
    assert!(after < before / 10.0);
    assert!((100.0 * before - 32.0).abs() <= 0.05, "raw {before}");
    readme_figure(
        "ck_explorer |B| spread, %",
        100.0 * after,
        1.26,
        0.005,
        pts.len(),
    );
}

/// Recordings that cannot support a 3-D calibration are refused with a reason.
#[test]
fn sunsided_3d_refusals() {
    for rec in [
        "rotate-ccw-around-z-pointing-up",
        "pan-along-z-pointing-up",
        "unmoved-with-x-pointing-forward",
    ] {
        let Some(pts) = sunsided_mag(rec) else { return };
        let r = fit_ellipsoid(&pts, &EllipsoidConfig::default());
        println!("3-D fit on {rec}: {:?}", r.as_ref().map(|s| s.quality));
        assert!(r.is_err());
    }
}
