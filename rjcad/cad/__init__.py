"""The solids (made with OpenCASCADE through OCP, ``occ``): spiral springs, the joint module, the finger; their
meshes and files."""
