"""`cmake --install` puts an importable package under the prefix."""
import os
import subprocess
import sys

from conftest import BUILD


def test_install_component_python(tmp_path):
    subprocess.run(["cmake", "--install", str(BUILD), "--prefix", str(tmp_path), "--component", "python"],
                   check=True, capture_output=True)
    site = next(tmp_path.glob("lib/python3*/dist-packages"))
    env = dict(os.environ, PYTHONPATH=str(site))
    r = subprocess.run([sys.executable, "-c", "import geode; print(geode.__file__, len(geode.template('geode2d').quads))"],
                       env=env, capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    path, quads = r.stdout.split()
    assert path.startswith(str(site)) and quads == "5"
