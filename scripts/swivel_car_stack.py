"""
Run the stack's nodes the way `ros2 run` runs them.

The installed executables under ros2_ws/install/<pkg>/lib/<pkg>/, each in its own process on
a chosen ROS domain.

Used by the demo (scripts/demo.py) and by the tests (through tests/support).
"""

from __future__ import annotations

import os
from pathlib import Path
import signal
import subprocess
import tempfile
import time
from typing import Any, Callable, Iterable, Mapping, Sequence

REPO_ROOT = Path(__file__).resolve().parents[1]
INSTALL_DIR = Path(os.environ.get('SWIVEL_CAR_INSTALL', REPO_ROOT / 'ros2_ws' / 'install'))


# Fast DDS 2.14's shared memory transport does not survive a peer killed with kill -9: a port
# the dead process was writing into, or one named after its reused participant id, stays
# unreachable (eProsima/Fast-DDS#5053, #5469). Over this profile a node uses UDP on 127.0.0.1
# only, discovering peers there as rmw_fastrtps' LOCALHOST range does.
LOOPBACK_UDP_PROFILE = Path(__file__).resolve().with_name('fastdds_loopback_udp.xml')


def ros_environment(domain_id: int) -> dict[str, str]:
    """Return the environment for a node process on ``domain_id``, heard only on this host."""
    env = dict(os.environ)
    env['ROS_DOMAIN_ID'] = str(domain_id)
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['PYTHONUNBUFFERED'] = '1'
    return env


def executable_path(package: str, executable: str) -> Path:
    """Where colcon installed ``executable`` of ``package``: where `ros2 run` looks."""
    path = INSTALL_DIR / package / 'lib' / package / executable
    if not path.is_file():
        raise FileNotFoundError(f'{path} does not exist: build the workspace (make build)')
    return path


def _parameter_argument(name: str, value: Any) -> str:
    if isinstance(value, bool):
        text = 'true' if value else 'false'
    elif isinstance(value, (list, tuple)):
        text = '[' + ','.join(str(v) for v in value) + ']'
    else:
        text = str(value)
    return f'{name}:={text}'


class NodeProcess:
    """
    A node executable running in its own process.

    Its output goes to a log file in the temporary directory while it runs; once the process
    is stopped or killed, the output is kept in memory and the file deleted.

    Parameters
    ----------
    package, executable : str
        As for `ros2 run`.
    domain_id : int
        ROS_DOMAIN_ID of the process.
    parameters : mapping
        ``-p name:=value`` overrides.
    params_file : path, optional
        A ``--params-file``.
    loopback_udp : bool
        Talk over UDP on 127.0.0.1 only (``LOOPBACK_UDP_PROFILE``), not over Fast DDS's
        shared memory, for a node that may be killed with kill -9 (see that profile).

    """

    def __init__(self, package: str, executable: str, domain_id: int,
                 parameters: Mapping[str, Any] | None = None,
                 params_file: Path | None = None, extra_args: Iterable[str] = (),
                 loopback_udp: bool = False) -> None:
        self.name = f'{package}/{executable}'
        environment = ros_environment(domain_id)
        if loopback_udp:
            # rmw_fastrtps' LOCALHOST range adds shared memory whatever the profile says.
            environment['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'SYSTEM_DEFAULT'
            environment['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(LOOPBACK_UDP_PROFILE)
        command = [str(executable_path(package, executable)), *extra_args, '--ros-args']
        if params_file is not None:
            command += ['--params-file', str(params_file)]
        for name, value in (parameters or {}).items():
            command += ['-p', _parameter_argument(name, value)]
        self.log = tempfile.NamedTemporaryFile(
            prefix=f'{executable}-', suffix='.log', delete=False)
        self._final_output: str | None = None
        self.process = subprocess.Popen(
            command, env=environment, stdout=self.log,
            stderr=subprocess.STDOUT, start_new_session=True)

    def output(self) -> str:
        """Everything the process printed so far (kept once it is stopped or killed)."""
        if self._final_output is not None:
            return self._final_output
        return Path(self.log.name).read_text(errors='replace')

    def _forget_log(self) -> None:
        """Keep the output of the ended process in memory and delete its log file, once."""
        if self._final_output is not None:
            return
        self._final_output = self.output()
        self.log.close()
        Path(self.log.name).unlink(missing_ok=True)

    def running(self) -> bool:
        return self.process.poll() is None

    def wait_for_output(self, text: str, timeout: float) -> None:
        """
        Wait until the process has printed ``text`` (a log line that says it is up).

        AssertionError with its output if it ends first or after ``timeout`` wall seconds (a
        guard against a hang, not a measurement).
        """
        deadline = time.monotonic() + timeout
        while text not in self.output():
            assert self.running() and time.monotonic() < deadline, \
                f'{self.name} did not print {text!r}:\n{self.output()[-3000:]}'
            time.sleep(0.05)

    def stop(self, timeout: float = 10.0) -> int:
        """SIGINT, then SIGKILL after ``timeout`` seconds; returns the exit code."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(timeout)
            except subprocess.TimeoutExpired:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait()
        self._forget_log()
        return self.process.returncode

    def kill(self) -> None:
        """SIGKILL, as a crash would end it."""
        os.killpg(self.process.pid, signal.SIGKILL)
        self.process.wait()
        self._forget_log()


def process_report(processes: Iterable[NodeProcess], chars: int = 1500) -> str:
    """Each process: running or its exit code, and the last ``chars`` of what it printed."""
    return '\n'.join(
        f'--- {p.name}: {"running" if p.running() else f"exited {p.process.returncode}"}'
        f'\n{p.output()[-chars:]}' for p in processes)


def config_path(package: str, file_name: str) -> Path:
    """Return an installed parameter file: share/<package>/config/<file_name>."""
    path = INSTALL_DIR / package / 'share' / package / 'config' / file_name
    if not path.is_file():
        raise FileNotFoundError(f'{path} does not exist: build the workspace (make build)')
    return path


def start_node(package: str, executable: str, domain_id: int,
               parameters: Mapping[str, Any], loopback_udp: bool = False) -> NodeProcess:
    """
    Start an installed node with its package's parameter file and ``parameters`` on top.

    The file is share/<package>/config/<executable>.yaml; ``loopback_udp`` as for
    `NodeProcess`.
    """
    return NodeProcess(package, executable, domain_id, parameters,
                       params_file=config_path(package, f'{executable}.yaml'),
                       loopback_udp=loopback_udp)


def lockstep_parameters(executable: str, lockstep_timeout: float,
                        real_time_factor: float = 1.0,
                        cmd_vel_driver: bool = False) -> dict[str, Any]:
    """
    Return the parameters that put ``executable`` into the lockstep chain.

    The chain of docs/architecture.md: the sim waits for the controller's command of each state (at
    most ``lockstep_timeout`` wall seconds), the controller for the planner's command of the state
    before, and with ``cmd_vel_driver`` for a driver's cmd_vel stamped with it. The sim is paced
    at ``real_time_factor`` (0: none) so that nodes outside the chain, publishing cmd_vel, keep
    up.
    """
    if executable == 'sim_node':
        return {'lockstep': True, 'lockstep_timeout': lockstep_timeout,
                'lockstep_real_time_factor': real_time_factor}
    if executable == 'controller_node':
        return {'lockstep_swivel_command': True, 'lockstep_cmd_vel': cmd_vel_driver,
                'lockstep_wait': lockstep_timeout / 2.0}
    return {}


class ResentRequest:
    """
    A service request sent again every ``resend_after`` wall seconds [s] until one is answered.

    For a request that may come twice. A server that has not yet discovered the client's
    response reader drops the response (rclpy logs "failed to send response ... (timeout)"),
    though the client already sees the service ready; under load that window outlasted the
    discovery waits. Spin until ``done()``, then take ``result()``.
    """

    def __init__(self, client: Any, request: Any, resend_after: float) -> None:
        self._client, self._request, self._resend_after = client, request, resend_after
        self._start = time.monotonic()  # [s]
        self._futures = [client.call_async(request)]

    def done(self) -> bool:
        """Tell whether one copy is answered; send another when one is due."""
        if any(future.done() for future in self._futures):
            return True
        if time.monotonic() > self._start + self._resend_after * len(self._futures):
            self._futures.append(self._client.call_async(self._request))
        return False

    def result(self) -> Any:
        """Return the response of the first copy answered."""
        return next(future for future in self._futures if future.done()).result()


def spin_until(executor: Any, condition: Callable[[], bool], timeout: float,
               what: str = 'condition', processes: Sequence[NodeProcess] = ()) -> None:
    """
    Spin ``executor`` until ``condition()`` holds.

    TimeoutError after ``timeout`` wall seconds (a guard against a hang, not a measurement),
    with what each of ``processes`` printed: the only trace of why a wait ran out.
    """
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            report = f'\n{process_report(processes)}' if processes else ''
            raise TimeoutError(f'timed out after {timeout} s waiting for {what}{report}')
        executor.spin_once(timeout_sec=0.05)
