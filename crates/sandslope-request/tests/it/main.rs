//! The request crate's integration tests in one test binary (one link, not three): arrays,
//! the field tables, and the requests.

mod arrays;
mod fields;
mod requests;
