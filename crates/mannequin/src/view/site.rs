//! What `mannequin view` serves for a path: the embedded page, `/scene.json` (the layers to
//! show), files generated for the scene (an avatar's skinned mesh with its motion, and its
//! Gaussians with their skinning), and the files under the viewed folder.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use burn::tensor::Device;
use mannequin_avatar::{AVATAR_DILATION, Avatar, export};
use mannequin_body::Motion;
use mannequin_io::PlyHeader;
use mannequin_mesh::gltf::{check_glb, scene_glb_bytes};
use mannequin_splat::SplatScene;
use serde_json::{Value, json};

use super::http::{Response, content_type, resolve};

const INDEX: &[u8] = include_bytes!("../../viewer/src/index.html");
const VIEWER: &[u8] = include_bytes!("../../viewer/dist/viewer.js");

/// 3DGS's screen-space dilation, for splat files from other tools.
const DILATION_3DGS: f64 = 0.3;

/// The procedural walk an avatar plays when no motion is given: seconds and frames per second.
const WALK: (f32, f32) = (4.0, 30.0);

/// One thing the page draws: a glTF scene (meshes, skeletons, animation) or Gaussian splats,
/// which follow a glTF layer's skeleton when `skeleton` names it.
struct Layer {
    name: String,
    url: String,
    kind: &'static str,
    skeleton: Option<String>,
    visible: bool,
    /// Splats' screen-space dilation (pixels² added to each footprint's covariance): an avatar's
    /// own (its renders use it), else 3DGS's 0.3.
    dilation: Option<f64>,
}

pub struct Site {
    /// The folder whose files are served (canonical).
    root: PathBuf,
    manifest: Vec<u8>,
    generated: HashMap<String, (&'static str, Vec<u8>)>,
}

impl Site {
    /// The site for `path`: an avatar folder (playing `motions` and those in the folder, else a
    /// procedural walk; with its dataset `data`, a test view beside its ground truth), a folder
    /// of `.glb` and 3DGS `.ply` files (`dress` and `cloth simulate` outputs, exports), or one
    /// such file.
    pub fn load(path: &Path, motions: &[PathBuf], data: Option<&Path>) -> Result<Self> {
        let full =
            path.canonicalize().with_context(|| format!("{}: no such file or folder", path.display()))?;
        let (root, files) = if full.is_dir() {
            (full.clone(), sorted_files(&full)?)
        } else {
            let parent = full.parent().context("a file has a parent folder")?.to_path_buf();
            (parent, vec![full.clone()])
        };
        let mut site = Site { root, manifest: Vec::new(), generated: HashMap::new() };
        let mut layers = Vec::new();
        let is_avatar = full.is_dir() && full.join("avatar.json").is_file();
        let mut extra: Value = json!({});
        if is_avatar {
            extra["motions"] = site.add_avatar(&full, &files, motions, &mut layers)?;
            if let Some(data) = data {
                extra["compare"] = site.add_compare(&full, data)?;
            }
        } else if !motions.is_empty() || data.is_some() {
            bail!(
                "{}: --motion and --data apply to an avatar folder (one holding avatar.json)",
                path.display()
            );
        }
        site.add_files(&files, &mut layers)?;
        if layers.is_empty() {
            bail!(
                "{}: nothing to show; expected an avatar folder (avatar.json), .glb files or 3DGS .ply files",
                path.display()
            );
        }
        let title =
            full.file_name().map_or_else(|| full.display().to_string(), |n| n.to_string_lossy().into_owned());
        let layers: Vec<Value> = layers
            .iter()
            .map(|l| json!({
                    "name": l.name, "url": l.url, "kind": l.kind, "skeleton": l.skeleton, "visible": l.visible,
                    "dilation": l.dilation,
                }))
            .collect();
        let mut manifest = json!({ "title": title, "layers": layers });
        if let (Some(m), Value::Object(e)) = (manifest.as_object_mut(), extra) {
            m.extend(e);
        }
        site.manifest = serde_json::to_vec_pretty(&manifest)?;
        Ok(site)
    }

    /// The avatar's skinned mesh and its Gaussians skinned to the same skeleton, and a glTF of
    /// the mesh per motion the page offers: `motions` (the `--motion` files), then the motion
    /// files among the folder's `files`, or a procedural walk when there are none. Returns the motions' names
    /// and URLs; the first is the mesh layer's own.
    fn add_avatar(
        &mut self,
        dir: &Path,
        files: &[PathBuf],
        motions: &[PathBuf],
        layers: &mut Vec<Layer>,
    ) -> Result<Value> {
        let avatar = Avatar::load(dir, &Device::flex())?;
        let canonical = avatar.canonical_pose()?;
        let mut named: Vec<(String, Motion)> = Vec::new();
        for p in motions {
            named.push((stem(p), Motion::read(p)?));
        }
        for p in files.iter().filter(|p| p.extension().is_some_and(|e| e == "npz")) {
            // The avatar's own files are not motions.
            if ["avatar.npz", "checkpoint.npz"].iter().any(|n| p.ends_with(n)) {
                continue;
            }
            match Motion::read(p) {
                Ok(m) => named.push((stem(p), m)),
                Err(e) => tracing::warn!("{}: not offered as a motion ({e})", p.display()),
            }
        }
        if named.is_empty() {
            named.push(("procedural walk".into(), Motion::walk_cycle(WALK.0, WALK.1)));
        }
        // Garment layers are nodes of their own, so each is a toggle.
        let (body, garments) = export::skinned_layers(&avatar, &canonical)?;
        let mut offered = Vec::new();
        for (k, (name, motion)) in named.iter().enumerate() {
            let animation = avatar.animation(motion)?;
            let glb =
                scene_glb_bytes(&dir.join(format!("{name}.glb")), &body, &garments, Some(&animation), &[])?;
            self.generated.insert(format!("motion_{k}.glb"), ("model/gltf-binary", glb));
            offered.push(json!({ "name": name, "url": format!("/generated/motion_{k}.glb") }));
        }
        let splats = export::skinned_gaussians_ply(&avatar, &canonical)?;
        self.generated.insert("gaussians.ply".into(), ("application/octet-stream", splats));
        layers.push(Layer {
            name: "avatar mesh".into(),
            url: "/generated/motion_0.glb".into(),
            kind: "glb",
            skeleton: None,
            // The Gaussians are the avatar; its mesh carries their skeleton and is a toggle.
            visible: false,
            dilation: None,
        });
        layers.push(Layer {
            name: "avatar".into(),
            url: "/generated/gaussians.ply".into(),
            kind: "splats",
            skeleton: Some("avatar mesh".into()),
            visible: true,
            dilation: Some(AVATAR_DILATION),
        });
        Ok(json!({ "layer": "avatar mesh", "choices": offered }))
    }

    /// The first novel-view image `eval` rendered and the dataset's ground truth of that view.
    fn add_compare(&mut self, dir: &Path, data: &Path) -> Result<Value> {
        let rendered = dir.join("eval/novel_view/images");
        let first = sorted_files(&rendered)
            .with_context(|| format!("{}: run `mannequin eval` on the avatar first", rendered.display()))?
            .into_iter()
            .find(|p| p.extension().is_some_and(|e| e == "png"))
            .with_context(|| format!("{}: no .png rendered by `mannequin eval`", rendered.display()))?;
        let name = first.file_name().context("a file has a name")?;
        let truth = data.join("test/novel_view/images").join(name);
        let bytes = std::fs::read(&truth)
            .with_context(|| format!("{}: the ground truth of {}", truth.display(), first.display()))?;
        self.generated.insert("truth.png".into(), ("image/png", bytes));
        let relative = first.strip_prefix(&self.root).context("eval images lie in the avatar folder")?;
        Ok(json!({ "render": format!("/files/{}", relative.display()), "truth": "/generated/truth.png" }))
    }

    /// Every `.glb` as a glTF layer and every 3DGS `.ply` as splats; splats carrying skinning
    /// (`joint_0`) follow the first glTF layer.
    fn add_files(&mut self, files: &[PathBuf], layers: &mut Vec<Layer>) -> Result<()> {
        let extension = |p: &Path| p.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        let url = |p: &Path| -> Result<String> {
            let name = p.file_name().context("a file has a name")?.to_string_lossy();
            Ok(format!("/files/{}", name.replace('%', "%25").replace(' ', "%20").replace('#', "%23")))
        };
        let first_glb = layers.len();
        for p in files.iter().filter(|p| extension(p).as_deref() == Some("glb")) {
            // Served only once it parses: a broken file is refused here, not in the browser.
            let bytes = std::fs::read(p).with_context(|| format!("reading {}", p.display()))?;
            check_glb(p, &bytes)?;
            layers.push(Layer {
                name: stem(p),
                url: url(p)?,
                kind: "glb",
                skeleton: None,
                visible: true,
                dilation: None,
            });
        }
        let skeleton = layers.get(first_glb).filter(|l| l.kind == "glb").map(|l| l.name.clone());
        for p in files.iter().filter(|p| extension(p).as_deref() == Some("ply")) {
            let bytes = std::fs::read(p).with_context(|| format!("reading {}", p.display()))?;
            PlyHeader::parse(&bytes).with_context(|| format!("{}: not a readable PLY", p.display()))?;
            if SplatScene::from_ply_bytes(p, &bytes).is_err() {
                tracing::info!("{}: not 3DGS splats (no f_dc/scale/rot properties); not shown", p.display());
                continue;
            }
            let header_end = bytes.len().min(64 * 1024);
            let skinned = String::from_utf8_lossy(&bytes[..header_end]).contains("property float joint_0\n");
            // Skinned splats are an avatar's (`export --skinned-gaussians`), drawn as it draws them.
            let (skeleton, dilation) =
                if skinned { (skeleton.clone(), AVATAR_DILATION) } else { (None, DILATION_3DGS) };
            layers.push(Layer {
                name: stem(p),
                url: url(p)?,
                kind: "splats",
                skeleton,
                visible: true,
                dilation: Some(dilation),
            });
        }
        Ok(())
    }

    /// The response to a GET of `path` (the URL's path, still %-encoded).
    pub fn get(&self, path: &str) -> Response {
        let ok = |content_type: &'static str, body: Vec<u8>| Response { status: 200, content_type, body };
        match path {
            "/" | "/index.html" => ok("text/html; charset=utf-8", INDEX.to_vec()),
            "/viewer.js" => ok("text/javascript; charset=utf-8", VIEWER.to_vec()),
            "/scene.json" => ok("application/json", self.manifest.clone()),
            _ => {
                if let Some(name) = path.strip_prefix("/generated/") {
                    return match self.generated.get(name) {
                        Some((t, bytes)) => ok(t, bytes.clone()),
                        None => Response::text(404, "no such file"),
                    };
                }
                let Some(rest) = path.strip_prefix("/files/") else {
                    return Response::text(404, "no such page");
                };
                match resolve(&self.root, rest) {
                    Ok(file) => match std::fs::read(&file) {
                        Ok(bytes) => ok(content_type(&file), bytes),
                        Err(_) => Response::text(404, "unreadable"),
                    },
                    Err(refusal) => refusal,
                }
            }
        }
    }
}

/// A file's name without its extension.
fn stem(path: &Path) -> String {
    path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

/// The regular files directly in `dir`, by name.
fn sorted_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("listing {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    Ok(files)
}
