//! Model export: GLB, glTF, OBJ+MTL.
