//! The bad-input table (`bad_inputs.json`) as Rust values, for the CLI's and the C API's
//! tests (included by `#[path]`; Python reads the same JSON).

#![allow(dead_code)] // each front end reads the fields it needs

use serde_json::Value;

/// One sample's values, in storage order.
#[derive(Debug, Clone, Copy)]
pub struct Row {
    pub t: f64,
    pub q: [f64; 4],
    pub rho: [f64; 3],
    pub tau: [f64; 3],
    pub w: Option<[f64; 3]>,
}

/// One bad input and what every front end must say of it.
#[derive(Debug, Clone)]
pub struct Case {
    pub name: String,
    pub rows: Vec<Row>,
    pub memory_s: Option<f64>,
    pub kind: String,
    pub sample: Option<usize>,
    pub c: Option<String>,
}

fn number(v: &Value) -> f64 {
    match v {
        Value::String(s) => match s.as_str() {
            "nan" => f64::NAN,
            "inf" => f64::INFINITY,
            "-inf" => f64::NEG_INFINITY,
            other => panic!("value {other:?}"),
        },
        v => v.as_f64().expect("a number"),
    }
}

/// The table's cases.
pub fn cases() -> Vec<Case> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/bad_inputs.json"
    );
    let table: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let base = &table["base"];
    let (dt, rate) = (
        base["dt_s"].as_f64().unwrap(),
        base["rate_rad_s"].as_f64().unwrap(),
    );
    let n_base = base["n"].as_u64().unwrap() as usize;
    let clean = |k: usize| {
        let t = k as f64 * dt;
        let half = rate * t / 2.0;
        Row {
            t,
            q: [0.0, 0.0, half.sin(), half.cos()],
            rho: [0.1 + 0.001 * k as f64, 0.2, 0.3],
            tau: [0.0; 3],
            w: Some([0.0, 0.0, rate]),
        }
    };
    let cases = table["cases"].as_array().unwrap();
    cases
        .iter()
        .map(|c| {
            let n = c["n"].as_u64().map_or(n_base, |n| n as usize);
            let mut rows: Vec<Row> = (0..n).map(clean).collect();
            for s in c["set"].as_array().into_iter().flatten() {
                let r = &mut rows[s["sample"].as_u64().unwrap() as usize];
                let k = s["component"].as_u64().unwrap_or(0) as usize;
                let v = number(&s["value"]);
                match s["field"].as_str().unwrap() {
                    "t" => r.t = v,
                    "q" => r.q[k] = v,
                    "rho" => r.rho[k] = v,
                    "tau" => r.tau[k] = v,
                    "w" => r.w.as_mut().unwrap()[k] = v,
                    f => panic!("field {f}"),
                }
            }
            if let Some(from) = c["w_absent_from"].as_u64() {
                for r in &mut rows[from as usize..] {
                    r.w = None;
                }
            }
            Case {
                name: c["name"].as_str().unwrap().into(),
                rows,
                memory_s: c["memory_s"].as_f64(),
                kind: c["kind"].as_str().unwrap().into(),
                sample: c["sample"].as_u64().map(|s| s as usize),
                c: c["c"].as_str().map(Into::into),
            }
        })
        .collect()
}
