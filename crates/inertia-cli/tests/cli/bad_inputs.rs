//! The bad-input table (`tests/data/bad_inputs.json`) through `inertia estimate --json`
//! on a CSV file: the JSON error's kind and sample are the table's (as C's and Python's).

#[path = "../../../../tests/data/bad_inputs.rs"]
mod table;

use std::io::Write as _;

fn csv(rows: &[table::Row]) -> String {
    let w = rows.iter().any(|r| r.w.is_some());
    let mut s = String::from("t,q_x,q_y,q_z,q_w,rho_x,rho_y,rho_z,tau_x,tau_y,tau_z");
    s += if w { ",w_x,w_y,w_z\n" } else { "\n" };
    for r in rows {
        let v: Vec<String> = [r.t]
            .iter()
            .chain(&r.q)
            .chain(&r.rho)
            .chain(&r.tau)
            .map(|x| format!("{x:?}"))
            .collect();
        s += &v.join(",");
        if w {
            s += &match r.w {
                Some(w) => format!(",{:?},{:?},{:?}", w[0], w[1], w[2]),
                None => ",,,".into(),
            };
        }
        s += "\n";
    }
    s
}

#[test]
fn the_cli_refuses_the_tables_inputs_with_its_kinds() {
    let dir = tempfile::tempdir().unwrap();
    for (k, case) in table::cases().iter().enumerate() {
        let path = dir.path().join(format!("case{k}.csv"));
        std::fs::File::create(&path)
            .unwrap()
            .write_all(csv(&case.rows).as_bytes())
            .unwrap();
        let p = path.to_str().unwrap();
        let memory = case.memory_s.map(|m| m.to_string());
        let mut args = vec!["estimate", p, "--json"];
        if let Some(m) = &memory {
            args.extend(["--memory", m]);
        }
        let o = super::inertia(&args);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{}: {}",
            case.name,
            super::stderr(&o)
        );
        let e = &super::json(&o)["error"];
        assert_eq!(e["kind"], case.kind.as_str(), "{}: {e}", case.name);
        assert_eq!(
            e["sample"].as_u64().map(|s| s as usize),
            case.sample,
            "{}: {e}",
            case.name
        );
        // The sample's line: the header is line 1.
        if let Some(s) = case.sample {
            assert_eq!(e["line"], s as u64 + 2, "{}: {e}", case.name);
        }
    }
}
