% SPDX-License-Identifier: Apache-2.0
function makeInfo = rtwmakecfg()
% RTWMAKECFG  Build information for code generated from the ccomm blocks:
% Simulink Coder calls this when a model uses sfun_ccomm_read or sfun_ccomm_write.
% CCOMM_PREFIX: where ccomm is installed for the target (default /usr; for a cross
% build, the target sysroot's prefix).
here = fileparts(mfilename('fullpath'));
prefix = getenv('CCOMM_PREFIX');
if isempty(prefix)
    prefix = '/usr';
end
makeInfo.includePath = {here, fullfile(prefix, 'include')};
makeInfo.sourcePath = {here};
makeInfo.linkLibsObjs = {fullfile(prefix, 'lib', 'libccomm.so')};
end
