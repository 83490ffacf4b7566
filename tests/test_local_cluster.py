"""The local Dask cluster of `oceanmc sweep --workers N` (sweeps/execute.py local_client) starts
quietly where another program, such as a user's own Dask dashboard, holds port 8787, and keeps
its HTTP routes on 127.0.0.1."""
import contextlib
import socket
import warnings

from oceanmc.sweeps.execute import local_client

DASK_DEFAULT_PORT = 8787


def test_a_local_cluster_starts_quietly_beside_another_on_port_8787():
    with contextlib.ExitStack() as stack:
        holder = stack.enter_context(socket.socket())
        try:
            holder.bind(("127.0.0.1", DASK_DEFAULT_PORT))
            holder.listen()
        except OSError:
            pass   # already held by another program: the case this test is about
        with warnings.catch_warnings():
            # distributed warned 'Port 8787 is already in use' (a UserWarning) before
            warnings.simplefilter("error")
            with local_client(1) as client:
                assert client.submit(sum, [1, 2]).result() == 3
                http = client.cluster.scheduler.http_server
                address = (http.address, http.port)
    assert address[0] == "127.0.0.1" and address[1] != DASK_DEFAULT_PORT, address
