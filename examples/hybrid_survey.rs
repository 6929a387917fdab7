//! A survey of random hybrids against their membership test: the first
//! `--count` hybrids (default 100) that [`testing::hybrid_node`] draws,
//! the same way every run, with a surface in their ball, and 10,000 points
//! within 2% of the bailout of each one's surface, checked with
//! [`testing::check_never_overestimates`] at the drawn estimate (the safety
//! factor applied). Prints each hybrid whose estimate overestimates
//! anywhere, with the largest factor found, and a summary line; exits
//! with status 1 when any does.
//!
//! `cargo run --release --features proptest --example hybrid_survey [-- --count N]`

use std::process::ExitCode;

use fractal_sdf::cpu;
use fractal_sdf::scene::Kind;
use fractal_sdf::testing::{self, check_never_overestimates, hybrid_inside};
use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::TestRunner;

fn main() -> ExitCode {
    let mut args = pico_args::Arguments::from_env();
    let wanted: usize = args
        .opt_value_from_str("--count")
        .expect("--count takes a number")
        .unwrap_or(100);
    let mut runner = TestRunner::deterministic();
    let strategy = testing::hybrid_node();
    let (mut surveyed, mut drawn, mut balls, mut failing) = (0, 0u64, 0, 0);
    while surveyed < wanted && drawn < 10 * wanted as u64 {
        drawn += 1;
        let node = strategy.new_tree(&mut runner).expect("a hybrid").current();
        let Kind::Hybrid(h) = node.kind() else {
            unreachable!("the strategy draws hybrids")
        };
        let bailout = h.bailout.default_value();
        let inside = |p| hybrid_inside(p, h);
        // Most random hybrids are empty or dust: a quick look first.
        if testing::near_surface_points(inside, bailout, 0.02 * bailout, 50, drawn).len() < 50 {
            continue;
        }
        let points = testing::near_surface_points(inside, bailout, 0.02 * bailout, 10_000, drawn);
        if points.len() < 10_000 {
            continue;
        }
        surveyed += 1;
        let eval = cpu::Evaluator::new(&node).expect("a valid hybrid");
        match check_never_overestimates(&eval, inside, &points, 8) {
            Ok(tested) => balls += tested.balls,
            Err(e) => {
                failing += 1;
                println!("overestimates {:.2} times: {h:?}", e.factor());
            }
        }
    }
    println!(
        "{surveyed} of {drawn} random hybrids with a surface, 10,000 points each: \
         {failing} overestimate ({balls} balls passed in the others)"
    );
    if failing == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
