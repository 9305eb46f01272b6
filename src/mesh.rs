//! Triangle meshes: OBJ loading and procedural shapes.
