% SPDX-License-Identifier: Apache-2.0
function makeInfo = rtwmakecfg()
% RTWMAKECFG  Build information for code generated from the ccomm blocks:
% Simulink Coder calls this when a model uses sfun_ccomm_read or sfun_ccomm_write.
%
% Finds libccomm where it is installed: CCOMM_PREFIX (default /usr; for a cross build,
% the target sysroot's /usr), then, under PREFIX/lib, the Debian multiarch directory
% (CCOMM_MULTIARCH, e.g. aarch64-linux-gnu or arm-linux-gnueabihf; default the one of
% this MATLAB's platform), any other */libccomm.so, PREFIX/lib64 and PREFIX/lib. Stops
% with an error naming every place it looked if there is none.
here = fileparts(mfilename('fullpath'));
prefix = getenv('CCOMM_PREFIX');
if isempty(prefix)
    prefix = '/usr';
end
libdir = fullfile(prefix, 'lib');
triplet = getenv('CCOMM_MULTIARCH');
if isempty(triplet)
    triplet = host_multiarch();
end
candidates = {};
if ~isempty(triplet)
    candidates{end + 1} = fullfile(libdir, triplet, 'libccomm.so');
end
others = dir(fullfile(libdir, '*-linux-gnu*', 'libccomm.so'));
for k = 1:numel(others)
    candidates{end + 1} = fullfile(libdir, others(k).name, 'libccomm.so'); %#ok<AGROW>
end
% dir() on a wildcard directory lists the file, not its directory, on some releases:
others = dir(fullfile(libdir, '*-linux-gnu*'));
for k = 1:numel(others)
    if others(k).isdir
        candidates{end + 1} = fullfile(libdir, others(k).name, 'libccomm.so'); %#ok<AGROW>
    end
end
candidates{end + 1} = fullfile(prefix, 'lib64', 'libccomm.so');
candidates{end + 1} = fullfile(libdir, 'libccomm.so');
lib = '';
for k = 1:numel(candidates)
    if exist(candidates{k}, 'file') == 2
        lib = candidates{k};
        break;
    end
end
if isempty(lib)
    error('ccomm:rtwmakecfg', ['ccomm: libccomm.so not found; looked in:\n  %s\n' ...
          'Install ccomm (Debian: apt install libccomm-dev) or set CCOMM_PREFIX ' ...
          '(and CCOMM_MULTIARCH for a cross build).'], strjoin(unique(candidates, 'stable'), '\n  '));
end
makeInfo.includePath = {here, fullfile(prefix, 'include')};
makeInfo.sourcePath = {here};
makeInfo.linkLibsObjs = {lib};
end

function triplet = host_multiarch()
% The Debian multiarch triplet of the platform MATLAB (or Octave) runs on.
switch computer('arch')
    case {'glnxa64', 'x86_64-pc-linux-gnu'}
        triplet = 'x86_64-linux-gnu';
    case {'glnxa32', 'glnx86'}
        triplet = 'i386-linux-gnu';
    case {'glnxarm64', 'maca64', 'aarch64-unknown-linux-gnu'}
        triplet = 'aarch64-linux-gnu';
    otherwise
        triplet = '';
end
end
