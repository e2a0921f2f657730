//! Every file reader against thousands of seeded mutations of the fuzz seed corpus
//! (`fuzz/corpus/<target>`): bit flips, byte sets, truncations, huge counts written over or into
//! the numbers of a header, and duplicated or dropped chunks. Each case must give `Ok` or `Err`:
//! never a panic (caught per case and reported with its seed and mutations), and never an
//! allocation that the input does not justify (a counting allocator bounds the peak bytes live
//! during a parse by a multiple of the input length). A hang has no timer here: the readers check
//! every count against the bytes left before looping by it, so a regression shows as a test that
//! never ends. The stable-toolchain stand-in for `cargo +nightly fuzz run` (see `fuzz/`); it
//! lives in the command line's crate because that crate depends on every reader: images and label
//! maps (data), `.garment` files (garment) and checkpoints (cloth, avatar) as well as the arrays,
//! meshes, motions, splats and cameras below them.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::io::Write;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use mannequin_body::{Motion, parse_model};
use mannequin_data::Image;
use mannequin_data::labels::LabelMap;
use mannequin_io::npy::parse_npy;
use mannequin_io::rng::SplitMix64;
use mannequin_io::{NpyArray, Npz, NpzWriter};
use mannequin_mesh::Obj;
use mannequin_splat::{SplatScene, parse_camera_json};

/// Counts the bytes each thread holds, so tests running side by side do not see each other.
struct Counting;

thread_local! {
    static LIVE: Cell<usize> = const { Cell::new(0) };
    static PEAK: Cell<usize> = const { Cell::new(0) };
}

fn grow(bytes: usize) {
    let live = LIVE.get() + bytes;
    LIVE.set(live);
    PEAK.set(PEAK.get().max(live));
}

fn shrink(bytes: usize) {
    LIVE.set(LIVE.get().saturating_sub(bytes));
}

// SAFETY: every call is forwarded to the system allocator unchanged; only counters are updated.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grow(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            grow(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        shrink(layout.size());
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            shrink(layout.size());
            grow(new_size);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Peak bytes live on this thread while `f` runs, above what was live before (its result
/// included).
fn peak_bytes<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let base = LIVE.get();
    PEAK.set(base);
    let r = f();
    (r, PEAK.get() - base)
}

/// What a reader may hold for an input of `len` bytes: decoding widens values (a `uint8` index
/// list becomes `u32` triangles, an `|S1` string a `String`), so a fixed multiple, plus a
/// constant for the zip reader's and the JSON parser's own tables (the zip reader sizes its table
/// of entries by the count an end record declares, at most 65,535, before reading them: about
/// 420 KB for a small archive whose central directory was copied over its start).
fn allowance(len: usize) -> usize {
    64 * len + (512 << 10)
}

/// Mutated cases per reader, spread evenly over its seeds.
const CASES: usize = 40_000;

/// Numbers a crafted header would declare: they must be refused before anything loops or
/// allocates by them (2⁶² overflows once multiplied by four, as a `U` dtype's width is).
const HUGE: [&str; 7] =
    ["99999999999", "18446744073709551615", "4294967295", "4611686018427387904", "-1", "0", "1e308"];

fn corpus(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus").join(target);
    let mut seeds: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| {
            let path = entry.unwrap().path();
            let bytes = std::fs::read(&path).unwrap();
            (path, bytes)
        })
        .collect();
    seeds.sort();
    assert!(!seeds.is_empty(), "{}: no seeds", dir.display());
    seeds
}

/// Applies one random mutation to `b`, returning what it did for the failure report.
fn mutate(b: &mut Vec<u8>, rng: &mut SplitMix64) -> String {
    if b.is_empty() {
        b.push(rng.next_u64() as u8);
        return "push".into();
    }
    let at = rng.below(b.len());
    match rng.below(8) {
        0 => {
            let bit = rng.below(8);
            b[at] ^= 1 << bit;
            format!("flip bit {bit} of byte {at}")
        }
        1 => {
            let v = [0, 0xff, 0x7f, 0x80, rng.next_u64() as u8][rng.below(5)];
            b[at] = v;
            format!("set byte {at} to {v:#04x}")
        }
        2 => {
            b.truncate(at);
            format!("truncate to {at}")
        }
        3 => {
            // Over a decimal number in the text (a PLY or .npy header count, a JSON size, an OBJ
            // index), or anywhere when the input has none.
            let digits: Vec<usize> = (0..b.len()).filter(|&i| b[i].is_ascii_digit()).collect();
            let start = if digits.is_empty() { at } else { digits[rng.below(digits.len())] };
            let end = (start..b.len()).find(|&i| !b[i].is_ascii_digit()).unwrap_or(b.len()).max(start);
            let huge = HUGE[rng.below(HUGE.len())];
            b.splice(start..end, huge.bytes());
            format!("number at {start}..{end} := {huge}")
        }
        4 => {
            let word: &[u8] = match rng.below(3) {
                0 => &u32::MAX.to_le_bytes(),
                1 => &u64::MAX.to_le_bytes(),
                _ => &(i32::MAX as u32).to_be_bytes(),
            };
            let end = (at + word.len()).min(b.len());
            b.splice(at..end, word.iter().copied());
            format!("binary count {word:02x?} over byte {at}")
        }
        5 => {
            let len = 1 + rng.below(64.min(b.len() - at));
            let chunk = b[at..at + len].to_vec();
            let to = rng.below(b.len() + 1);
            b.splice(to..to, chunk);
            format!("duplicate {at}..{} at {to}", at + len)
        }
        6 => {
            let len = 1 + rng.below(16.min(b.len() - at));
            b.drain(at..at + len);
            format!("drop {at}..{}", at + len)
        }
        _ => {
            let v = rng.next_u64() as u8;
            b.insert(at, v);
            format!("insert {v:#04x} at {at}")
        }
    }
}

/// Runs `read` on [`CASES`] mutations of the seeds of `target`, within [`allowance`].
fn mutations(target: &str, read: impl Fn(&[u8]) -> Result<(), String>) {
    mutations_of(target, &corpus(target), allowance, read);
}

/// [`mutations`] with another bound on the bytes a case may hold.
fn mutations_within(target: &str, most: usize, read: impl Fn(&[u8]) -> Result<(), String>) {
    mutations_of(target, &corpus(target), |len| allowance(len).max(most), read);
}

/// Runs `read` on [`CASES`] mutations (one to three each) of `seeds`, after checking that every
/// seed itself reads, holding each case to `limit` of its length in bytes.
fn mutations_of(
    target: &str,
    seeds: &[(PathBuf, Vec<u8>)],
    limit: impl Fn(usize) -> usize,
    read: impl Fn(&[u8]) -> Result<(), String>,
) {
    for (path, bytes) in seeds {
        read(bytes).unwrap_or_else(|e| panic!("seed {} does not read: {e}", path.display()));
    }
    let mut ok = 0;
    for case in 0..CASES {
        let (path, seed) = &seeds[case % seeds.len()];
        let mut rng = SplitMix64::new(case as u64 ^ 0x6d75_7461_7465);
        let mut bytes = seed.clone();
        let done: Vec<String> = (0..1 + rng.below(3)).map(|_| mutate(&mut bytes, &mut rng)).collect();
        let report = || format!("{target} case {case}: seed {}, mutations {done:?}", path.display());
        let (result, peak) = peak_bytes(|| catch_unwind(AssertUnwindSafe(|| read(&bytes))));
        let result = result.unwrap_or_else(|_| panic!("{}: the reader panicked", report()));
        assert!(
            peak <= limit(bytes.len()),
            "{}: {peak} bytes live for {} bytes of input",
            report(),
            bytes.len()
        );
        ok += usize::from(result.is_ok());
    }
    // Some mutations must leave a readable file, or the cases never get past the first check.
    assert!(ok > 0, "{target}: no mutated case read");
}

fn npz(bytes: &[u8]) -> Result<Npz, String> {
    Npz::from_bytes("case.npz".into(), bytes).map_err(|e| e.to_string())
}

/// Motion and model parsing, on archives whose checksums still hold.
fn read_motion(npz: &Npz) -> Result<(), String> {
    let m = Motion::from_npz(npz).map_err(|e| e.to_string())?;
    m.resample(m.fps).map_err(|e| e.to_string())?;
    m.frame_pose(0, 24).map_err(|e| e.to_string()).map(drop)
}

#[test]
fn npy() {
    mutations("npy", |b| parse_npy(b).map(drop).map_err(|e| e.to_string()));
}

#[test]
fn npz_and_body_models() {
    mutations("npz", |b| {
        let npz = npz(b)?;
        if npz.contains("v_template") {
            parse_model(&npz, None).map_err(|e| e.to_string())?;
        }
        Ok(())
    });
}

#[test]
fn motions() {
    mutations("motion", |b| read_motion(&npz(b)?));
}

/// Archive checksums stop most byte mutations at the zip layer; mutating one member's `.npy`
/// bytes and storing it again, with a fresh checksum, reaches the array header parser and the
/// motion and model readers behind it.
#[test]
fn npz_members_behind_valid_checksums() {
    let repack = |seed: &[u8], member: usize, rng: &mut SplitMix64| -> Vec<u8> {
        let mut archive = zip::ZipArchive::new(std::io::Cursor::new(seed)).unwrap();
        let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let stored =
            zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
        let members = archive.len();
        for i in 0..members {
            let mut entry = archive.by_index(i).unwrap();
            let mut data = Vec::new();
            std::io::Read::read_to_end(&mut entry, &mut data).unwrap();
            if i == member % members {
                for _ in 0..1 + rng.below(2) {
                    mutate(&mut data, rng);
                }
            }
            out.start_file(entry.name(), stored).unwrap();
            out.write_all(&data).unwrap();
        }
        out.finish().unwrap().into_inner()
    };
    for target in ["motion", "npz"] {
        let seeds = corpus(target);
        for case in 0..CASES / 2 {
            let (path, seed) = &seeds[case % seeds.len()];
            let mut rng = SplitMix64::new(case as u64 ^ 0x6d65_6d62);
            let bytes = repack(seed, rng.below(16), &mut rng);
            let report = || format!("{target} member case {case}: seed {}", path.display());
            let (result, peak) = peak_bytes(|| {
                catch_unwind(AssertUnwindSafe(|| {
                    let npz = npz(&bytes)?;
                    if npz.contains("v_template") {
                        parse_model(&npz, None).map(drop).map_err(|e| e.to_string())
                    } else {
                        read_motion(&npz)
                    }
                }))
            });
            assert!(result.is_ok(), "{}: the reader panicked", report());
            assert!(peak <= allowance(bytes.len()), "{}: {peak} bytes live for {}", report(), bytes.len());
        }
    }
}

#[test]
fn mesh_ply() {
    mutations("mesh_ply", |b| {
        mannequin_mesh::ply::parse(Path::new("case.ply"), b).map(drop).map_err(|e| e.to_string())
    });
}

#[test]
fn obj() {
    mutations("obj", |b| Obj::parse(Path::new("case.obj"), b).map(drop).map_err(|e| e.to_string()));
}

#[test]
fn pc2() {
    mutations("pc2", |b| {
        mannequin_mesh::PointCache::parse(Path::new("case.pc2"), b).map(drop).map_err(|e| e.to_string())
    });
}

#[test]
fn splat_ply() {
    mutations("splat_ply", |b| {
        let scene = SplatScene::from_ply_bytes(Path::new("case.ply"), b).map_err(|e| e.to_string())?;
        scene.gaussians().validate_shapes().map_err(|e| e.to_string())
    });
}

#[test]
fn camera_json() {
    mutations("camera_json", |b| {
        parse_camera_json(Path::new("case.json"), b).map(drop).map_err(|e| e.to_string())
    });
}

/// Runs `read` on the bytes written to a file of this thread's own, for readers that take a path.
fn via_file(name: &str, bytes: &[u8], read: impl FnOnce(&Path) -> Result<(), String>) -> Result<(), String> {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("parser_mutations");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{:?}-{name}", std::thread::current().id()).replace(['(', ')'], ""));
    std::fs::write(&path, bytes).unwrap();
    read(&path)
}

/// What an image reader may hold: the pixels a header declares are legitimately allocated before
/// the data proves them (a PNG of one colour compresses to almost nothing), so the bound is the
/// decoded image at the pixel limit, as `f32` RGB plus the decoder's RGBA buffer.
const IMAGE_ALLOWANCE: usize = mannequin_io::limits::MAX_IMAGE_PIXELS * (12 + 4);

#[test]
fn images() {
    mutations_within("image", IMAGE_ALLOWANCE, |b| {
        Image::decode(Path::new("case.png"), b).map(drop).map_err(|e| e.to_string())
    });
}

#[test]
fn label_maps() {
    mutations_within("label_map", IMAGE_ALLOWANCE, |b| {
        via_file("labels.png", b, |p| {
            LabelMap::read_png_with_legend(p, 3).map(drop).map_err(|e| e.to_string())
        })
    });
}

#[test]
fn garments() {
    mutations("garment", |b| {
        via_file("case.garment", b, |p| {
            mannequin_garment::file::read_garment(p).map(drop).map_err(|e| e.to_string())
        })
    });
}

/// The record a cloth run's checkpoint carries, as the simulating commands write one.
#[derive(serde::Serialize)]
struct ClothRun {
    material: String,
    substeps: u32,
    frames: usize,
}

/// A cloth simulation's checkpoint (its record, state and frames so far) and the training
/// checkpoint's record and counters: written by the writers, then mutated.
#[test]
fn checkpoints() {
    use mannequin_cloth::run_checkpoint::{add_state, check_run, frames_array, read_frames, read_state};
    let run = ClothRun { material: "cotton".into(), substeps: 20, frames: 2 };
    let state = mannequin_cloth::ClothState {
        positions: vec![[0.0, 1.0, 0.0], [0.1, 1.0, 0.0], [0.0, 1.1, 0.0], [0.1, 1.1, 0.05]],
        velocities: vec![[0.0, -0.1, 0.0]; 4],
    };
    let mut w = NpzWriter::new();
    mannequin_io::run_record::write_run(&mut w, &run);
    add_state(&mut w, &state, "");
    w.add("frames", frames_array(&[state.positions.clone(), state.positions.clone()], 4));
    let cloth = w.to_bytes();
    let training = training_checkpoint();
    let seeds = [
        (PathBuf::from("cloth checkpoint"), cloth),
        (PathBuf::from("training checkpoint"), training.1.clone()),
    ];
    mutations_of("checkpoint", &seeds, allowance, |b| {
        let npz = npz(b)?;
        if npz.contains("iteration") {
            return via_file("checkpoint.npz", b, |p| {
                mannequin_avatar::Checkpoint::open(p, &training.0, &[]).map(drop).map_err(|e| e.to_string())
            });
        }
        check_run(&npz, &run).map_err(|e| e.to_string())?;
        read_state(&npz, 4, "").map_err(|e| e.to_string())?;
        read_frames(&npz, "frames", 4).map(drop).map_err(|e| e.to_string())
    });
}

/// A training run's record and a checkpoint of it at iteration 3 (counters only: the arrays are
/// read as the trainer resumes, through the same `Npz` readers the other cases mutate).
fn training_checkpoint() -> (mannequin_avatar::TrainingRun, Vec<u8>) {
    use mannequin_avatar::{AvatarConfig, Method, SkirtMode, TrainOptions, TrainingRun};
    let hash = "0123456789abcdef".to_string();
    let run = TrainingRun {
        body: "default".into(),
        downscale: 1,
        skirt: SkirtMode::Auto,
        garments: None,
        data: mannequin_io::fingerprint::Fingerprint {
            files: 3,
            bytes: 1000,
            listing: hash.clone(),
            cameras: hash.clone(),
            poses: hash,
        },
        avatar: AvatarConfig::new(Method::Tavatar, 0),
        options: TrainOptions::new(Method::Tavatar, 10, 0),
    };
    let mut w = NpzWriter::new();
    run.write(&mut w);
    w.add("iteration", NpyArray::i64(vec![1], vec![3]));
    w.add("adam_step", NpyArray::i64(vec![1], vec![3]));
    (run, w.to_bytes())
}
