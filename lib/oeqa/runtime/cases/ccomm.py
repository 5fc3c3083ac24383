# SPDX-License-Identifier: Apache-2.0
"""testimage cases for ccomm-image: the daemon is up and a signal makes a round trip
through the shared-memory store (ccomm pub -> ccomm echo) on the booted target."""

import json
import re
import time

from oeqa.core.decorator.depends import OETestDepends
from oeqa.runtime.case import OERuntimeTestCase
from oeqa.runtime.decorator.package import OEHasPackage


class CcommTest(OERuntimeTestCase):

    def _run(self, cmd, timeout=30):
        status, output = self.target.run(cmd, timeout=timeout)
        return status, output.strip()

    @OETestDepends(['ssh.SSHTest.test_ssh'])
    @OEHasPackage(['ccomm'])
    def test_ccommd_active(self):
        # Type=notify: "active" only after ccommd has mapped its segment and said READY=1;
        # give a slow emulated board time to get there.
        state = ''
        for _ in range(30):
            _, state = self._run('systemctl is-active ccommd.service')
            if state in ('active', 'failed'):
                break
            time.sleep(1)
        if state != 'active':
            _, log = self._run('systemctl status --no-pager ccommd.service; '
                               'journalctl --no-pager -b -u ccommd.service | tail -n 40')
            self.fail('ccommd.service is %r, not active:\n%s' % (state, log))
        status, output = self._run('systemctl is-enabled ccommd.service')
        self.assertEqual(status, 0, msg='ccommd.service is not enabled: %s' % output)

    def _local_double_signal(self):
        """A double signal this board produces, from the installed signals.xml as ccommd
        reads it (ccommd --check --json: the one parser of the file)."""
        status, node = self._run('hostname')
        self.assertEqual(status, 0, msg=node)
        status, resolved = self._run('ccommd --check /etc/ccomm/signals.xml --json')
        self.assertEqual(status, 0, msg=resolved)
        for sig in json.loads(resolved)['signals']:
            if sig['producer'] == node and sig['type'] == 'double':
                return sig['name']
        self.skipTest('/etc/ccomm/signals.xml has no double signal produced by node %r' % node)

    @OETestDepends(['ccomm.CcommTest.test_ccommd_active'])
    @OEHasPackage(['ccomm-cli'])
    def test_signal_roundtrip(self):
        name = self._local_double_signal()

        status, output = self._run('ccomm list')
        self.assertEqual(status, 0, msg='ccomm list failed: %s' % output)
        self.assertRegex(output, r'(^|\s)%s(\s|$)' % re.escape(name),
                         msg='ccomm list does not show %s:\n%s' % (name, output))

        # 42.125 is exact in binary, so any printf-style rendering contains "42.125".
        # echo subscribes first (and must see exactly one new value), then pub writes it.
        value = '42.125'
        # busybox may lack timeout(1): a background sleeper kills a hung echo instead
        cmd = ('o=$(mktemp); ccomm echo {n} --count 1 > $o 2>&1 & e=$!; '
               '(sleep 15; kill $e) >/dev/null 2>&1 & w=$!; '
               'sleep 1; ccomm pub {n} {v}; pub=$?; '
               'wait $e; erc=$?; kill $w 2>/dev/null; '
               'echo "pub-rc=$pub echo-rc=$erc"; cat $o; rm -f $o').format(n=name, v=value)
        status, output = self._run(cmd, timeout=40)
        self.assertIn('pub-rc=0', output, msg='ccomm pub failed:\n%s' % output)
        self.assertIn('echo-rc=0', output, msg='ccomm echo did not see one update:\n%s' % output)
        self.assertRegex(output, r'42\.125', msg='value did not round-trip:\n%s' % output)

