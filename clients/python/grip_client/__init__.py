"""grip_client: a standard-library client for the grip contact solver service.

    from grip_client import Client, GripError
    job = Client("http://127.0.0.1:8080").submit("scene.json")
    print(job.wait()["status"], job.result()["summary"])

`python3 -m grip_client --help` for the command line; plots (`grip_client.plots`) need
matplotlib (Debian: python3-matplotlib, under /usr/bin/python3).
"""

from .client import FINISHED_STATUSES, TERMINAL_EVENTS, Client, Event, GripError, Job

__all__ = ["Client", "Job", "Event", "GripError", "TERMINAL_EVENTS", "FINISHED_STATUSES"]
__version__ = "0.1.0"
