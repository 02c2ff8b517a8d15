"""SIM/host/host.json, the scene as vfield describes it to hosts (written by
`vfield simulate` and `vfield export-scene`; plugin/include/vfield/host/host_scene.h
documents every key). Plain Python: nothing here needs Blender."""

import json
import os


class HostSceneError(Exception):
    """A simulation folder that cannot be imported; the message names the file."""


class HostScene:
    """host.json read and checked, its paths made absolute."""

    def __init__(self, simulation_dir):
        self.simulation_dir = os.path.abspath(simulation_dir)
        self.path = os.path.join(self.simulation_dir, "host", "host.json")
        if not os.path.isfile(self.path):
            raise HostSceneError(
                f"{self.path}: not found; is {self.simulation_dir} a vfield simulation folder? "
                "(`vfield export-scene SCENE --sim DIR` writes it for a folder simulated before)"
            )
        try:
            with open(self.path, encoding="utf-8") as f:
                data = json.load(f)
        except (OSError, ValueError) as e:
            raise HostSceneError(f"{self.path}: unreadable: {e}") from None
        if data.get("format") != "vfield host scene" or data.get("version") != 1:
            raise HostSceneError(f"{self.path}: not a vfield host scene of version 1")
        try:
            self.scene_file = data["scene"]
            self.fps = float(data["fps"])
            self.frame_start, self.frame_end = (int(v) for v in data["frames"])
            self.volume = data["volume"]
            self.objects = data["objects"]
            self.camera = data["camera"]
            self.sun = data["sun"]
            self.sky = data["sky"]
            tracks = data["tracks"]
        except (KeyError, TypeError, ValueError) as e:
            raise HostSceneError(f"{self.path}: missing or malformed entry {e}") from None
        here = os.path.dirname(self.path)
        self.density_pattern = os.path.normpath(os.path.join(here, self.volume["files"]))
        for obj in self.objects:
            obj["mesh"] = os.path.join(here, obj["mesh"])
        self.tracks = self._read_tracks(os.path.normpath(os.path.join(here, tracks))) if tracks else {}

    @property
    def name(self):
        """The scene file's name without its extension."""
        return os.path.splitext(os.path.basename(self.scene_file))[0]

    def density_file(self, frame):
        return self.density_pattern.replace("####", f"{frame:04d}")

    @staticmethod
    def _read_tracks(path):
        """{object name: [(frame, 4x4 matrix rows, column vectors)]} from tracks.json."""
        try:
            with open(path, encoding="utf-8") as f:
                objects = json.load(f)["objects"]
            return {
                name: [(int(e["frame"]), [e["matrix"][r * 4 : r * 4 + 4] for r in range(4)]) for e in entries]
                for name, entries in objects.items()
            }
        except (OSError, ValueError, KeyError, TypeError) as e:
            raise HostSceneError(f"{path}: unreadable tracks: {e}") from None


def read_obj(path):
    """Vertices and triangles of an OBJ as vfield writes it (v and f lines)."""
    vertices, triangles = [], []
    try:
        with open(path, encoding="utf-8") as f:
            for line in f:
                if line.startswith("v "):
                    vertices.append(tuple(float(v) for v in line.split()[1:4]))
                elif line.startswith("f "):
                    triangles.append(tuple(int(v.split("/")[0]) - 1 for v in line.split()[1:]))
    except (OSError, ValueError) as e:
        raise HostSceneError(f"{path}: unreadable mesh: {e}") from None
    return vertices, triangles
