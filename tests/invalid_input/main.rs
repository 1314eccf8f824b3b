//! Invalid and degenerate input: constructors reject invalid parameters with
//! `Error::InvalidParameter` (`constructors`), degenerate but legal inputs give finite results
//! (`degenerate`), every entry point follows the invalid-input policy for bad directions
//! (`policy`), the renderer layer answers the inputs a real pipeline sends and rejects the
//! rest at their boundaries (`renderer`), and −0 is treated like +0 (`negative_zero`).

mod constructors;
mod degenerate;
mod negative_zero;
mod policy;
mod renderer;
