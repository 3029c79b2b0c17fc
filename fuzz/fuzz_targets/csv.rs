//! The schedule CSV writer and reader: any text read gives a schedule or an error, and what is
//! read or built writes out and reads back to the same schedule (to the 8 decimals written).
#![no_main]

use libfuzzer_sys::fuzz_target;
use sunlit::export::Schedule;
use sunlit::year::samples::Timesteps;

fuzz_target!(|data: &[u8]| {
    if let Ok(schedule) = Schedule::from_csv("fuzz.csv", &String::from_utf8_lossy(data)) {
        round_trip(&schedule);
    }
    if let Some(schedule) = built(data) {
        round_trip(&schedule);
    }
});

/// A schedule made from the input: a few columns named by its first bytes (any text, so some
/// are refused by the writer), values from the rest (cycled over the year).
fn built(data: &[u8]) -> Option<Schedule> {
    let (&head, rest) = data.split_first()?;
    let timesteps = Timesteps::new([1, 2][usize::from(head & 1)]).ok()?;
    let columns = usize::from(head >> 1) % 4 + 1;
    let text = String::from_utf8_lossy(rest);
    let names: Vec<String> = (0..columns).map(|i| text.chars().skip(i * 3).take(3).collect()).collect();
    let mut schedule = Schedule::zeros(names, timesteps);
    let words: Vec<u32> = rest.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    if !words.is_empty() {
        for (i, v) in schedule.values.iter_mut().enumerate() {
            let w = words[i % words.len()];
            // Mostly fractions in [0, 1]; raw bit patterns (NaN, negatives, > 1) now and then.
            *v = if w & 0xff == 0xff { f32::from_bits(w) } else { w as f32 / u32::MAX as f32 };
        }
    }
    Some(schedule)
}

fn round_trip(schedule: &Schedule) {
    let Ok(text) = schedule.to_csv() else {
        // The writer refuses exactly what fails validation.
        assert!(schedule.validate().is_err());
        return;
    };
    let back = Schedule::from_csv("fuzz.csv", &text).expect("what is written reads back");
    assert_eq!((&back.names, back.timesteps), (&schedule.names, schedule.timesteps));
    for (a, b) in schedule.values.iter().zip(&back.values) {
        // 8 decimals (±5e-9), then the nearest f32 (±3e-8 below 1).
        assert!((a - b).abs() <= 4e-8, "{a} read back as {b}");
    }
}
