//! rcs-codegen: placeholder until the code-generation issue lands.
