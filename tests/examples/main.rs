//! The examples' code in `validation` run as tests: the report in its quick mode (`report`)
//! and the path tracer (`path_tracer`).

mod path_tracer;
mod report;
