//! Renders every comparison chart of `ronap_core::render` with made-up data to `/tmp/charts/*.png`,
//! to look at them: `cargo run --release -p ronap-core --example charts`.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ronap_core::eval::Outcome;
use ronap_core::render::{
    compare_chart, contact_sheet, grouped_bars, outcome_strip, Canvas, PolicyBars, Series,
    SheetRow, GOAL, PATH, START,
};
use ronap_core::{Aabb, Point, Scene};
use std::error::Error;
use std::path::Path;

/// The Wilson 95% interval of `k` successes out of `n`.
fn wilson(k: usize, n: usize) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let (n, p, z) = (n as f64, k as f64 / n as f64, 1.96);
    let centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
    let half = z / (1.0 + z * z / n) * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    [centre - half, centre + half]
}

/// `episodes` made-up episodes of a policy that succeeds with probability `skill`.
fn policy(rng: &mut ChaCha8Rng, name: &str, skill: f64, episodes: usize) -> PolicyBars {
    let spl: Vec<f64> = (0..episodes)
        .map(|_| {
            if rng.random::<f64>() < skill {
                (0.35 + 0.6 * skill * rng.random::<f64>().sqrt()).min(1.0)
            } else {
                0.0
            }
        })
        .collect();
    let wins = spl.iter().filter(|&&v| v > 0.0).count();
    PolicyBars {
        name: name.to_owned(),
        success_rate: wins as f64 / episodes.max(1) as f64,
        success_ci95: wilson(wins, episodes),
        spl,
    }
}

fn outcome(rng: &mut ChaCha8Rng, skill: f64) -> Outcome {
    let r = rng.random::<f64>();
    if r < skill {
        Outcome::Success
    } else {
        match ((r - skill) / (1.0 - skill) * 10.0) as u32 {
            0..=3 => Outcome::Timeout,
            4..=5 => Outcome::Stuck,
            6..=8 => Outcome::Collision,
            _ => Outcome::RewardMin,
        }
    }
}

/// A small made-up scene with a path drawn on it.
fn picture(rng: &mut ChaCha8Rng, w: f64, h: f64) -> ronap_core::render::Canvas {
    let boxes: Vec<Aabb> = (0..6)
        .map(|_| {
            let (x, y) = (rng.random::<f64>() * w, rng.random::<f64>() * h);
            Aabb::from_corners(Point::new(x, y), Point::new(x + 0.1 * w, y + 0.05 * h))
        })
        .collect();
    let scene = Scene::from_boxes(w, h, boxes, 5.0);
    let mut canvas = Canvas::new(&scene, 1.0);
    let points: Vec<Point> = (0..8)
        .map(|i| {
            let t = f64::from(i) / 7.0;
            Point::new(0.1 * w + 0.8 * w * t, 0.2 * h + 0.6 * h * t * t)
        })
        .collect();
    canvas.path(&points, 3.0, PATH);
    canvas.fill_disc(points[0], 6.0, START);
    canvas.fill_disc(points[7], 6.0, GOAL);
    canvas
}

fn main() -> Result<(), Box<dyn Error>> {
    let out = Path::new("/tmp/charts");
    std::fs::create_dir_all(out)?;
    let mut rng = ChaCha8Rng::seed_from_u64(7);

    let three = vec![
        policy(&mut rng, "greedy", 0.62, 1000),
        policy(&mut rng, "mlp", 0.84, 1000),
        policy(&mut rng, "wall-follower", 0.31, 1000),
    ];
    let title = "success = reached the goal within 10 px, 1000 seeds";
    compare_chart(title, &three).save(out.join("compare.png"))?;

    let mut many: Vec<PolicyBars> = (0..10)
        .map(|i| {
            let name = format!("mlp-checkpoint-epoch-{:03}-lr-3e-4", 10 * i);
            policy(&mut rng, &name, 0.08 * f64::from(i) + 0.15, 300)
        })
        .collect();
    many[3].success_rate = f64::NAN;
    many[3].spl.clear();
    compare_chart("ten policies, long names, one without figures", &many)
        .save(out.join("compare_many.png"))?;
    compare_chart("one policy", &three[1..2]).save(out.join("compare_one.png"))?;
    compare_chart("no policies", &[]).save(out.join("compare_empty.png"))?;

    let names: Vec<String> = ["greedy", "mlp", "wall-follower"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let skills = [0.62, 0.84, 0.31];
    for (file, seeds, first) in [("strip.png", 200, 1), ("strip_wrapped.png", 3000, 1000)] {
        let seed_ids: Vec<u64> = (first..first + seeds).collect();
        let outcomes: Vec<Vec<Outcome>> = skills
            .iter()
            .map(|&k| (0..seeds).map(|_| outcome(&mut rng, k)).collect())
            .collect();
        outcome_strip(&names, &seed_ids, &outcomes).save(out.join(file))?;
    }

    let columns = names.clone();
    let rows: Vec<SheetRow> = [17u64, 42, 123]
        .iter()
        .map(|seed| SheetRow {
            label: format!("seed {seed}"),
            cells: [(400.0, 300.0), (300.0, 300.0), (200.0, 400.0)]
                .iter()
                .zip([
                    "success, 212 steps",
                    "success, 180 steps",
                    "timeout, 500 steps",
                ])
                .map(|(&(w, h), caption)| (picture(&mut rng, w, h).into_image(), caption.into()))
                .collect(),
        })
        .collect();
    contact_sheet(&columns, &rows, 180).save(out.join("sheet.png"))?;

    let bins: Vec<String> = [
        "ratio 1.0-1.3",
        "ratio 1.3-1.6",
        "ratio 1.6-2.0",
        "ratio 2.0+",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let series: Vec<Series> = names
        .iter()
        .zip(skills)
        .map(|(name, skill)| Series {
            name: name.clone(),
            values: (0..4)
                .map(|b| {
                    let n = 250;
                    let rate = (skill * (1.15 - 0.2 * f64::from(b))).clamp(0.0, 1.0);
                    let k = (rate * f64::from(n)).round() as usize;
                    (k as f64 / f64::from(n), wilson(k, n as usize))
                })
                .collect(),
        })
        .collect();
    grouped_bars(
        "success by difficulty (path ratio), 1000 seeds",
        &bins,
        &series,
    )
    .save(out.join("grouped.png"))?;
    println!("charts written to {}", out.display());
    Ok(())
}
