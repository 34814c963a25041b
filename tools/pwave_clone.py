"""What tools/pwave-stations.py and tools/pwave-extra.py share: the commit of
github.com/vacalderon/GroundmotionSelection they read (PEER NGA-West2 records; Ancheta et al.
2014, Earthquake Spectra 30(3)), git on a clone of it or its bare git directory, and the exit
with a message naming the tool."""
import pathlib
import subprocess
import sys

COMMIT = "4575a07afb90e2a254291c19a0518df52a87846d"


def fail(message):
    print(f"{pathlib.Path(sys.argv[0]).name}: {message}", file=sys.stderr)
    sys.exit(1)


def git(clone, *args):
    base = ["git", "-C", clone] if (pathlib.Path(clone) / ".git").exists() else [
        "git", "--git-dir", clone]
    done = subprocess.run(base + list(args), capture_output=True)
    if done.returncode != 0:
        fail(f"git {' '.join(args)}: {done.stderr.decode(errors='replace').strip()}")
    return done.stdout
