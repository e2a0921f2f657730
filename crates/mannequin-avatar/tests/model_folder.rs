//! A model folder is one unit: `avatar.npz` carries the configuration with the parameters, so a
//! stale `avatar.json` (a crash between the two writes) cannot pair another configuration with
//! them, and folders written before that still load from `avatar.json`.

use std::path::PathBuf;

use burn::tensor::Device;
use mannequin_avatar::avatar::{CONFIG_FILE, PARAMS_FILE};
use mannequin_avatar::{Avatar, AvatarConfig, Canonical, Method};
use mannequin_body::BodyModel;
use mannequin_io::{Npz, NpzWriter};

fn saved(name: &str) -> (PathBuf, AvatarConfig) {
    let dir = std::env::temp_dir().join(format!("mannequin-model-folder-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let canonical = Canonical::from_body(&BodyModel::default_body_lod1(), &[0.0; 10], 0).unwrap();
    let mut config = AvatarConfig::new(Method::Tavatar, 3);
    // A small grid keeps the test quick; the code paths are the same.
    config.hash_log2_table = 12;
    Avatar::new(config.clone(), canonical, &Device::flex()).unwrap().save(&dir).unwrap();
    (dir, config)
}

#[test]
fn load_reads_the_configuration_saved_with_the_parameters() {
    let (dir, config) = saved("stale");
    // What a crash after writing avatar.npz would leave: the previous model's avatar.json.
    let mut previous = config.clone();
    previous.dilation = 0.3;
    previous.antialiased = true;
    std::fs::write(dir.join(CONFIG_FILE), serde_json::to_string(&previous).unwrap()).unwrap();
    assert_eq!(Avatar::load(&dir, &Device::flex()).unwrap().config, config);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_folder_saved_before_avatar_npz_held_the_configuration_still_loads() {
    let (dir, config) = saved("legacy");
    let path = dir.join(PARAMS_FILE);
    let npz = Npz::read(&path).unwrap();
    let mut w = NpzWriter::new();
    for key in npz.keys().filter(|k| *k != "config") {
        w.add(key, npz.get(key).unwrap().clone());
    }
    w.write(&path).unwrap();
    assert_eq!(Avatar::load(&dir, &Device::flex()).unwrap().config, config);
    std::fs::remove_dir_all(dir).unwrap();
}
