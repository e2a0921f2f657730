//! A SMPL-form `.pkl` (protocol 2, Python 2 strings, SciPy CSC regressors, a chumpy `Ch`
//! shapedirs; tools/oracles/body_pickle.py) loads directly, into the same model NumPy and SciPy
//! make of it (the `.npz` beside it); truncated or corrupted pickles are errors naming the file.

#[path = "common/scratch.rs"]
mod scratch;

use mannequin_body::{BodyModel, load_model};
use mannequin_io::Npz;
use scratch::Scratch;

fn fixture(name: &str) -> String {
    format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_pickle_loads_into_the_same_model_as_its_npz() {
    let pkl = BodyModel::from_spec(&fixture("smpl_form.pkl"), None).unwrap();
    let npz = BodyModel::from_spec(&fixture("smpl_form.npz"), None).unwrap();
    assert_eq!((pkl.num_vertices(), pkl.num_joints(), pkl.num_betas()), (12, 24, 10));
    assert_eq!(pkl.v_template, npz.v_template);
    assert_eq!(pkl.faces, npz.faces);
    assert_eq!(pkl.parents(), npz.parents());
    assert_eq!(pkl.shapedirs(), npz.shapedirs());
    assert_eq!(pkl.posedirs(), npz.posedirs());
    assert_eq!(pkl.j_regressor().to_dense(12), npz.j_regressor().to_dense(12));
    assert_eq!(pkl.weights(), npz.weights());
    // Every other array (J, the priors, vert_sym_idxs) is kept, identical; strings and the
    // nested dict are not arrays.
    assert_eq!(pkl.extras, npz.extras);
    assert!(pkl.extras.contains_key("J_regressor_prior") && !pkl.extras.contains_key("bs_type"));
    // Ten shape coefficients were asked for: the same truncation as for .npz.
    assert_eq!(BodyModel::from_spec(&fixture("smpl_form.pkl"), Some(4)).unwrap().num_betas(), 4);
}

#[test]
fn truncated_pickles_are_errors_naming_the_file() {
    let full = std::fs::read(fixture("smpl_form.pkl")).unwrap();
    let dir = Scratch::new("pkl-cut");
    for cut in [0, 1, 2, 40, full.len() / 3, full.len() / 2, full.len() - 1] {
        let path = dir.join(format!("cut_{cut}.pkl"));
        std::fs::write(&path, &full[..cut]).unwrap();
        let msg = load_model(&path, None).unwrap_err().to_string();
        assert!(msg.contains(&format!("cut_{cut}.pkl")) && !msg.contains('\n'), "{msg}");
    }
}

#[test]
fn a_model_key_that_is_not_an_array_is_named() {
    // {'v_template': 'abc'} at protocol 2: the model's first field is a string.
    let bytes = b"\x80\x02}q\x00U\x0av_templateq\x01U\x03abcs.";
    let dir = Scratch::new("pkl-string");
    let path = dir.join("strings.pkl");
    std::fs::write(&path, bytes).unwrap();
    let msg = load_model(&path, None).unwrap_err().to_string();
    assert!(msg.contains("strings.pkl") && msg.contains("'v_template'") && msg.contains("a string"), "{msg}");
}

/// Thousands of corrupted copies of the fixture give errors or arrays, never a panic (a
/// deterministic stand-in for a fuzzer, as for `.npz`).
#[test]
fn corrupted_pickles_never_panic() {
    let good = std::fs::read(fixture("smpl_form.pkl")).unwrap();
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..2000 {
        let mut bytes = good.clone();
        for _ in 0..1 + next() % 4 {
            let i = (next() % bytes.len() as u64) as usize;
            bytes[i] = next() as u8;
        }
        let cut = bytes.len() - (next() % 8) as usize;
        if let Ok(arrays) = Npz::from_pickle("fuzz.pkl".into(), &bytes[..cut]) {
            let _ = mannequin_body::parse_model(&arrays, None);
        }
    }
}
