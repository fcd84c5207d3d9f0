"""sim.World.from_yaml: a scene's text loaded as if it were a file, which a sweep's runs are (docs/sweeps.md).
Its truth is World(path) of a file holding the same text: the same loader, the same bits."""
import pickle
import shutil

import pytest

from conftest import ROOT, SCENES, same_bits
from soft_body_sim import sim

# A rope falling onto the example mesh, named by a path relative to the scene's folder.
RELATIVE_MESH_SCENE = """
physics: {integrator: semi_implicit_euler, dt: 0.001}
colliders:
  - {name: part, shape: mesh, mesh: meshes/part.stl, position: [0.5, 0.0, 0.85]}
bodies:
  - {name: rope, type: rope, nodes: 15, from: [0.0, 0.0, 1.0], to: [1.0, 0.0, 1.0], mass: 0.1, stiffness: 500.0,
     damping: 0.01, radius: 0.01, pinned: [0]}
"""


def test_text_steps_to_the_bits_of_the_file_and_finds_meshes_from_the_sources_folder(tmp_path):
    (tmp_path / "meshes").mkdir()
    shutil.copy(ROOT / "config" / "meshes" / "part.stl", tmp_path / "meshes" / "part.stl")
    scene = tmp_path / "falling.yaml"
    scene.write_text(RELATIVE_MESH_SCENE)
    from_file = sim.World(scene)
    # The source need not exist: only its folder is used, to find meshes/part.stl.
    from_text = sim.World.from_yaml(RELATIVE_MESH_SCENE, tmp_path / "run-7.yaml")
    assert from_text.scene == str(tmp_path / "run-7.yaml")
    from_file.step(400)
    from_text.step(400)
    assert same_bits(from_text.positions(), from_file.positions())

    # A world of text pickles with its text: no file to load again.
    copy = pickle.loads(pickle.dumps(from_text))
    copy.step(100)
    from_text.step(100)
    assert same_bits(copy.positions(), from_text.positions())


def test_the_loaders_line_names_the_source():
    text = (SCENES / "rope.yaml").read_text().replace("stiffness: 200.0", "stiffness: -5.0")
    with pytest.raises(sim.SceneError, match=r"^/some/folder/rope\.yaml:\d+: bodies\[0\]\.stiffness: "):
        sim.World.from_yaml(text, "/some/folder/rope.yaml")
