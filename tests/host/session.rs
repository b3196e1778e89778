use palpate::session::Scene;
use std::path::Path;

#[test]
fn probe() {
    let cases = [
        "colour = 1\n[material]\nyoung_pa = 1\npoisson = 0.3",
        "mesh = \"a.msh\"\nfix=[\"z<1\"]\n[material]\nyoung_pa = 1\npoisson = 0.3\n[tool]\nradius = 0.002",
        "mesh = \"a.msh\"\nfix=[\"z<1\"]\n",
        "mesh = \"a.msh\"\nfix=[\"z<1\"]\n[material]\nyoung_pa = 1\npoisson = 0.3\n[tool]\npoints = \"one\"",
        "mesh = \"a.msh\"\nfix=[\"z<1\"]\n[material]\nyoung_pa = 1\npoisson = 0.3\n[tool]\npoints = -1",
        "mesh = \"a.msh\"\nfix=[\"z<1\"]\n[material]\nyoung_pa = 1\npoisson = 0.3\n[model]\nkind = \"hybrid\"",
        "mesh = \"a.msh\"\nfix=[\"z<1\"]\n[material]\nyoung_pa = 1\npoisson = 0.3\n[model]\nkind = \"dynamic\"\nlaw = \"neo\"\ndamping_per_s = 1",
        "mesh = \"a.msh\"\nfix=[\"z<1\"]\n[material]\nyoung_pa = 1\npoisson = 0.3\n[generated]\nbox = [1,1,1]\ncells = [1,1,1]",
        "mesh = \"a.msh\"\nfix=[\"z<1\"]\n[material]\nyoung_pa = 1\npoisson = 0.3\nmesh = \"b\"",
        "mesh = \"a.msh\"\nfix=[\"z<1\"]\n[material]\nyoung_pa = 1\npoisson = 0.3\n[generated]\nbox_m = [1,1]\ncells = [1,1,1]",
    ];
    for c in cases {
        println!(
            "{:?}",
            Scene::from_toml_str_named(c, "bad.toml", Path::new("/s"))
                .map(|_| ())
                .map_err(|e| e.to_string())
        );
    }
}
