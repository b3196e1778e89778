//! Linear P1 finite elements: element stiffness and global assembly.
