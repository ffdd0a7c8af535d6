//! Compiles qhull's reentrant library (qhull/src/libqhull_r, the sources MuJoCo 4.0 builds as
//! qhullstatic_r) and the shim csrc/hull_graph.c with the platform's C compiler.

fn main() {
    const SOURCES: [&str; 16] = [
        "global_r.c",
        "stat_r.c",
        "geom2_r.c",
        "poly2_r.c",
        "merge_r.c",
        "libqhull_r.c",
        "geom_r.c",
        "poly_r.c",
        "qset_r.c",
        "mem_r.c",
        "random_r.c",
        "usermem_r.c",
        "userprintf_r.c",
        "io_r.c",
        "user_r.c",
        "accessors_r.c",
    ];
    let mut build = cc::Build::new();
    build.include("qhull/src").warnings(false);
    for s in SOURCES {
        let path = format!("qhull/src/libqhull_r/{s}");
        println!("cargo:rerun-if-changed={path}");
        build.file(path);
    }
    build.file("csrc/hull_graph.c");
    println!("cargo:rerun-if-changed=csrc/hull_graph.c");
    println!("cargo:rerun-if-changed=qhull/src/libqhull_r");
    build.compile("qhull_r_lagrange");
}
