"""Runs `vfield simulate` as a child process and follows its progress lines."""

import queue
import re
import shutil
import subprocess
import threading

PROGRESS = re.compile(r"frame (\d+)/(\d+)")


class SimulationError(Exception):
    """vfield refused the scene or failed; the message is its own last line."""


def find_vfield(configured):
    """The vfield executable: the add-on's preference, else `vfield` on PATH."""
    path = shutil.which(configured or "vfield")
    if path is None:
        raise SimulationError(f"vfield executable not found ({configured or 'vfield'}): set it in the add-on's preferences")
    return path


class Simulation:
    """`vfield simulate SCENE -o OUTPUT`, started at once; poll() while it runs."""

    def __init__(self, vfield, scene_file, output_dir):
        self.command = [vfield, "simulate", scene_file, "-o", output_dir]
        self.process = subprocess.Popen(self.command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self.lines = queue.Queue()
        self.last_line = ""
        self.log = []  # every line vfield printed, in order
        self.done, self.total = 0, 0
        self.status = ""
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        for line in self.process.stderr:
            self.lines.put(line.rstrip("\n"))

    def poll(self):
        """Takes in the lines printed so far; True once vfield has exited."""
        exited = self.process.poll() is not None
        if exited:
            self._reader.join()  # every line is in the queue
        while not self.lines.empty():
            line = self.lines.get_nowait()
            if not line:
                continue
            self.last_line = line
            self.log.append(line)
            # Every line is news: "preparing: terrain: exact distance field 54%" before the frames.
            self.status = "vfield: " + line
            match = PROGRESS.search(line)
            if match:
                self.done, self.total = int(match.group(1)), int(match.group(2))
        return exited

    def wait(self):
        self.process.wait()
        self.poll()
        self.check()

    def cancel(self):
        self.process.terminate()
        self.process.wait()

    def check(self):
        """Raises SimulationError unless vfield exited successfully."""
        if self.process.returncode != 0:
            raise SimulationError(self.last_line or f"{' '.join(self.command)} exited with {self.process.returncode}")
