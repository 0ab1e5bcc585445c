//! The study driver: a sweep of scene variants run resumably on one machine
//! or sharded over a cluster (issue #5).
