pub mod gltf_check;
