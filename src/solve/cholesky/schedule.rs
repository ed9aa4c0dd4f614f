//! The schedule of the factorisation on several threads (`solve::cholesky::subtrees`): the supernodal
//! elimination tree cut into tasks, whole subtrees at the bottom and single supernodes above them, each
//! task ready once the tasks below it are done, the ready task with the longest path of work to the root
//! taken first. The work of a supernode is what the left-looking kernel does for it: the multiply-adds of
//! the updates it receives from the supernodes below and of its own dense factor and solve.
//!
//! With the environment variable `TRESCA_SCHEDULE` set, the factorisation prints the schedule's work, its
//! critical path and its makespan simulated on the threads (all in multiply-adds) to standard error.

/// The environment variable that asks for the schedule's figures on standard error.
pub(super) const ENV: &str = "TRESCA_SCHEDULE";
pub(super) const NONE: usize = usize::MAX;

/// Subtrees are cut until none holds more than 1/(GRAIN · threads) of the work: small enough that the
/// threads finish the bottom of the tree within a small fraction of each other.
const GRAIN: f64 = 16.0;

/// The supernodal elimination tree with, for each supernode, the supernodes that update it and its work.
pub(super) struct Tree {
    /// The parent of each supernode, `NONE` at roots.
    pub parent: Vec<usize>,
    /// The supernodes that update supernode s, increasing: `updaters[update_ptr[s]..update_ptr[s + 1]]`.
    pub update_ptr: Vec<usize>,
    pub updaters: Vec<usize>,
    /// The multiply-adds of each supernode (see the module's text).
    pub work: Vec<f64>,
}

impl Tree {
    /// The tree of supernodes `begin[s]..end[s]` whose row patterns below their columns are `pattern(s)`.
    pub fn new<'p>(begin: &[usize], end: &[usize], n: usize, pattern: impl Fn(usize) -> &'p [usize]) -> Tree {
        let ns = begin.len();
        let mut of_col = vec![0; n];
        for s in 0..ns {
            of_col[begin[s]..end[s]].fill(s);
        }
        let parent: Vec<usize> = (0..ns).map(|d| pattern(d).first().map_or(NONE, |&r| of_col[r])).collect();
        let mut work: Vec<f64> = (0..ns)
            .map(|s| {
                let (w, below) = ((end[s] - begin[s]) as f64, pattern(s).len() as f64);
                w * w * w / 6.0 + w * w * below / 2.0
            })
            .collect();
        let mut pairs = Vec::new();
        for d in 0..ns {
            let (p, width) = (pattern(d), (end[d] - begin[d]) as f64);
            let mut lo = 0;
            while lo < p.len() {
                let s = of_col[p[lo]];
                let mid = p[lo..].partition_point(|&r| r < end[s]);
                // C[rows below, mid columns] −= A Bᵀ, its lower triangle: depth `width`
                let (rows, cols) = ((p.len() - lo) as f64, mid as f64);
                work[s] += width * cols * (rows - (cols - 1.0) / 2.0);
                pairs.push((s, d));
                lo += mid;
            }
        }
        let mut update_ptr = vec![0; ns + 1];
        pairs.iter().for_each(|&(s, _)| update_ptr[s + 1] += 1);
        (0..ns).for_each(|s| update_ptr[s + 1] += update_ptr[s]);
        let mut next = update_ptr.clone();
        let mut updaters = vec![0; pairs.len()];
        for (s, d) in pairs {
            updaters[next[s]] = d;
            next[s] += 1;
        }
        Tree { parent, update_ptr, updaters, work }
    }
}

/// The tasks: each a list of supernodes (increasing), the task above it, how many tasks below it, and
/// its priority (the work on its path to the root, its own included). A task's number is above those
/// of the tasks below it.
pub(super) struct Tasks {
    pub members: Vec<Vec<usize>>,
    pub parent: Vec<usize>,
    pub below: Vec<usize>,
    pub priority: Vec<f64>,
    pub work: Vec<f64>,
}

impl Tasks {
    /// The tasks of `tree` for `threads` threads: subtrees whose root is split off (a task of its own,
    /// its children's subtrees cut again) while they hold more than 1/(GRAIN · threads) of the work.
    pub fn new(tree: &Tree, threads: usize) -> Tasks {
        let ns = tree.parent.len();
        let mut sub = tree.work.clone();
        let mut children = vec![Vec::new(); ns];
        for s in 0..ns {
            if tree.parent[s] != NONE {
                sub[tree.parent[s]] += sub[s];
                children[tree.parent[s]].push(s);
            }
        }
        let total: f64 = tree.work.iter().sum();
        let limit = total / (GRAIN * threads as f64);
        // the root of each supernode's task: itself when split off or a subtree's root
        let mut head = vec![NONE; ns];
        let mut stack: Vec<usize> = (0..ns).filter(|&s| tree.parent[s] == NONE).collect();
        while let Some(r) = stack.pop() {
            head[r] = r;
            if sub[r] > limit && !children[r].is_empty() {
                stack.extend_from_slice(&children[r]);
            }
        }
        for s in (0..ns).rev() {
            if head[s] == NONE {
                head[s] = head[tree.parent[s]];
            }
        }
        // tasks numbered by their heads, increasing (a head is above every member of its task)
        let mut task_of = vec![NONE; ns];
        let mut members: Vec<Vec<usize>> = Vec::new();
        for s in 0..ns {
            if head[s] == s {
                task_of[s] = members.len();
                members.push(Vec::new());
            }
        }
        (0..ns).for_each(|s| members[task_of[head[s]]].push(s));
        let nt = members.len();
        let (mut parent, mut below, mut work) = (vec![NONE; nt], vec![0; nt], vec![0.0; nt]);
        for (t, list) in members.iter().enumerate() {
            work[t] = list.iter().map(|&s| tree.work[s]).sum();
            let &root = list.last().unwrap_or(&0);
            if let Some(&p) = (tree.parent[root] != NONE).then_some(&tree.parent[root]) {
                parent[t] = task_of[head[p]];
                below[parent[t]] += 1;
            }
        }
        let mut priority = work.clone();
        for t in (0..nt).rev() {
            if parent[t] != NONE {
                priority[t] += priority[parent[t]];
            }
        }
        Tasks { members, parent, below, priority, work }
    }

    /// The total work, the critical path (the most work on one path from a task to the root) and the
    /// makespan of the schedule simulated on `threads` threads, each task on one.
    pub fn figures(&self, threads: usize) -> (f64, f64, f64) {
        let total = self.work.iter().sum();
        let critical = self.priority.iter().copied().fold(0.0, f64::max);
        let nt = self.work.len();
        let mut below = self.below.clone();
        let mut ready: Vec<usize> = (0..nt).filter(|&t| below[t] == 0).collect();
        // (finish time, task) of the tasks running
        let mut running: Vec<(f64, usize)> = Vec::new();
        let mut now = 0.0f64;
        loop {
            while running.len() < threads && !ready.is_empty() {
                let i = (0..ready.len()).max_by(|&i, &j| self.priority[ready[i]].total_cmp(&self.priority[ready[j]]));
                let t = ready.swap_remove(i.unwrap_or(0));
                running.push((now + self.work[t], t));
            }
            let Some(i) = (0..running.len()).min_by(|&i, &j| running[i].0.total_cmp(&running[j].0)) else { break };
            let (end, t) = running.swap_remove(i);
            now = end;
            let p = self.parent[t];
            if p != NONE {
                below[p] -= 1;
                if below[p] == 0 {
                    ready.push(p);
                }
            }
        }
        (total, critical, now)
    }
}
