//! The schedule of the factorisation on several threads (`solve::cholesky::subtrees`): the supernodal
//! elimination tree cut into tasks, whole subtrees at the bottom and the supernodes above them in parts
//! (their updates from each task below, in order, then their dense work), each task ready once the tasks
//! it waits for are done, the ready task with the most work on a path from it to the end taken first. The work of a supernode is what the left-looking kernel does for it: the multiply-adds of
//! the updates it receives from the supernodes below and of its own dense factor and solve.
//!
//! With the environment variable `TRESCA_SCHEDULE` set, the factorisation prints the schedule's work, its
//! critical path, its makespan simulated on the threads and the work of the tasks that run alone in that
//! simulation (all in multiply-adds) to standard error.

/// The environment variable that asks for the schedule's figures on standard error.
pub(super) const ENV: &str = "TRESCA_SCHEDULE";
pub(super) const NONE: usize = usize::MAX;

/// Subtrees are cut until none holds more than 1/(GRAIN · threads) of the work: small enough that the
/// threads finish the bottom of the tree within a small fraction of each other.
const GRAIN: f64 = 16.0;

/// The supernodal elimination tree with, for each supernode, the supernodes that update it and its work.
/// Supernodes are counted in `u32` ([`fits_u32`]).
pub(super) struct Tree {
    /// The parent of each supernode, `NONE` at roots.
    pub parent: Vec<usize>,
    /// The supernodes that update supernode s, increasing: `updaters[update_ptr[s]..update_ptr[s + 1]]`,
    /// and the multiply-adds of each of these updates.
    pub update_ptr: Vec<usize>,
    pub updaters: Vec<u32>,
    pub update_work: Vec<f64>,
    /// The multiply-adds of each supernode's dense factor and solve.
    pub dense: Vec<f64>,
}

/// Whether `count` rows or supernodes can be numbered in `u32` with `u32::MAX` free for "none".
pub(super) fn fits_u32(count: usize) -> bool {
    count < u32::MAX as usize
}

/// `of_col` ← the supernode of each column, supernodes `begin[s]..end[s]`.
fn supernode_of_column(begin: &[usize], end: &[usize], of_col: &mut [u32]) {
    for s in 0..begin.len() {
        of_col[begin[s]..end[s]].fill(s as u32);
    }
}

/// Each update that supernode d sends, in increasing order of the supernode s it updates, from its row
/// pattern `p` below its columns: `f(s, lo, mid)`, s's rows being `p[lo..]` of which `p[lo..lo + mid]` are
/// s's columns.
fn updates_of(p: &[usize], of_col: &[u32], end: &[usize], mut f: impl FnMut(usize, usize, usize)) {
    let mut lo = 0;
    while lo < p.len() {
        let s = of_col[p[lo]] as usize;
        let mid = p[lo..].partition_point(|&r| r < end[s]);
        f(s, lo, mid);
        lo += mid;
    }
}

/// The number of updates between the supernodes `begin[s]..end[s]` (pairs of a supernode and one it updates).
pub(super) fn count_updates<'p>(
    begin: &[usize],
    end: &[usize],
    n: usize,
    pattern: impl Fn(usize) -> &'p [usize],
) -> usize {
    let mut of_col = vec![0u32; n];
    supernode_of_column(begin, end, &mut of_col);
    let mut count = 0;
    (0..begin.len()).for_each(|d| updates_of(pattern(d), &of_col, end, |_, _, _| count += 1));
    count
}

impl Tree {
    /// The tree of supernodes `begin[s]..end[s]` whose row patterns below their columns are `pattern(s)`,
    /// with `of_col` (one entry a column) as scratch.
    pub fn new<'p>(begin: &[usize], end: &[usize], of_col: &mut [u32], pattern: impl Fn(usize) -> &'p [usize]) -> Tree {
        let ns = begin.len();
        supernode_of_column(begin, end, of_col);
        let of_col = &*of_col;
        let parent: Vec<usize> = (0..ns).map(|d| pattern(d).first().map_or(NONE, |&r| of_col[r] as usize)).collect();
        let dense: Vec<f64> = (0..ns)
            .map(|s| {
                let (w, below) = ((end[s] - begin[s]) as f64, pattern(s).len() as f64);
                w * w * w / 6.0 + w * w * below / 2.0
            })
            .collect();
        // two passes over the patterns: the updates each supernode receives counted, then listed (in
        // increasing order of the updater, as d increases)
        let mut update_ptr = vec![0; ns + 1];
        (0..ns).for_each(|d| updates_of(pattern(d), of_col, end, |s, _, _| update_ptr[s + 1] += 1));
        (0..ns).for_each(|s| update_ptr[s + 1] += update_ptr[s]);
        let mut next = update_ptr.clone();
        let (mut updaters, mut update_work) = (vec![0u32; update_ptr[ns]], vec![0.0; update_ptr[ns]]);
        for d in 0..ns {
            let (p, width) = (pattern(d), (end[d] - begin[d]) as f64);
            updates_of(p, of_col, end, |s, lo, mid| {
                // C[rows below, mid columns] −= A Bᵀ, its lower triangle: depth `width`
                let (rows, cols) = ((p.len() - lo) as f64, mid as f64);
                updaters[next[s]] = d as u32;
                update_work[next[s]] = width * cols * (rows - (cols - 1.0) / 2.0);
                next[s] += 1;
            });
        }
        Tree { parent, update_ptr, updaters, update_work, dense }
    }

    /// The work of each supernode: its updates and its dense work.
    fn work(&self) -> Vec<f64> {
        (0..self.parent.len())
            .map(|s| self.dense[s] + self.update_work[self.update_ptr[s]..self.update_ptr[s + 1]].iter().sum::<f64>())
            .collect()
    }
}

/// What a task computes.
pub(super) enum Job {
    /// These supernodes (increasing) whole.
    Whole(Vec<usize>),
    /// Of supernode s, K's columns if `first`, then the updates `updaters[from..to]` in order.
    Update { s: usize, from: usize, to: usize, first: bool },
    /// The dense factor of supernode s and the solve below it, once its updates are done.
    Dense(usize),
}

/// The tasks: what each computes, the tasks that wait for it, how many it waits for, its work and its
/// priority (the most work on a path from it to the end, its own included). Tasks wait only for tasks
/// numbered before them.
pub(super) struct Tasks {
    pub jobs: Vec<Job>,
    pub next: Vec<Vec<usize>>,
    pub below: Vec<usize>,
    pub priority: Vec<f64>,
    pub work: Vec<f64>,
}

impl Tasks {
    /// The tasks of `tree` for `threads` threads. Subtrees are split (their root taken off, its children's
    /// subtrees cut again) while they hold more than 1/(GRAIN · threads) of the work; a subtree that is
    /// not split is one task. A supernode taken off is computed by several: one per task among those that
    /// computed its updaters (its updates from them, in order, as soon as they are done), then its dense work.
    pub fn new(tree: &Tree, threads: usize) -> Tasks {
        let own = tree.work();
        let (head, split) = cut(tree, &own, threads);
        let ns = own.len();
        let mut tasks =
            Tasks { jobs: Vec::new(), next: Vec::new(), below: Vec::new(), priority: Vec::new(), work: Vec::new() };
        // the task after which each supernode is done: first that of each subtree's head, in increasing order
        let mut done = vec![NONE; ns];
        let mut sizes = Vec::new();
        for h in (0..ns).filter(|&h| head[h] as usize == h && !split[h]) {
            done[h] = sizes.len();
            sizes.push(0);
        }
        (0..ns).filter(|&s| !split[s]).for_each(|s| sizes[done[head[s] as usize]] += 1);
        for size in sizes {
            tasks.add(Job::Whole(Vec::with_capacity(size)), &[], 0.0);
        }
        for s in (0..ns).filter(|&s| !split[s]) {
            let t = done[head[s] as usize];
            done[s] = t;
            let Job::Whole(list) = &mut tasks.jobs[t] else { unreachable!("the first tasks are whole subtrees") };
            list.push(s);
            tasks.work[t] += own[s];
        }
        drop((head, own));
        for s in (0..ns).filter(|&s| split[s]) {
            let (mut from, end) = (tree.update_ptr[s], tree.update_ptr[s + 1]);
            let mut prev =
                if from == end { tasks.add(Job::Update { s, from, to: end, first: true }, &[], 0.0) } else { NONE };
            while from < end {
                let by = done[tree.updaters[from] as usize];
                let to = from + tree.updaters[from..end].iter().take_while(|&&d| done[d as usize] == by).count();
                let work = tree.update_work[from..to].iter().sum();
                let job = Job::Update { s, from, to, first: prev == NONE };
                prev = tasks.add(job, &[by, prev], work);
                from = to;
            }
            done[s] = tasks.add(Job::Dense(s), &[prev], tree.dense[s]);
        }
        tasks.prioritise();
        tasks
    }

    /// A task computing `job`, waiting for the tasks `after` (`NONE` ignored).
    fn add(&mut self, job: Job, after: &[usize], work: f64) -> usize {
        let t = self.jobs.len();
        self.jobs.push(job);
        self.next.push(Vec::new());
        self.below.push(0);
        self.work.push(work);
        for &a in after.iter().filter(|&&a| a != NONE) {
            self.next[a].push(t);
            self.below[t] += 1;
        }
        t
    }

    fn prioritise(&mut self) {
        let nt = self.jobs.len();
        self.priority = self.work.clone();
        for t in (0..nt).rev() {
            let after = self.next[t].iter().map(|&u| self.priority[u]).fold(0.0, f64::max);
            self.priority[t] += after;
        }
    }

    /// The first column a task computes.
    pub fn first_supernode(&self, t: usize) -> usize {
        match &self.jobs[t] {
            Job::Whole(list) => list[0],
            Job::Update { s, .. } | Job::Dense(s) => *s,
        }
    }

    /// The total work, the critical path (the most work on one path of tasks), the makespan of the
    /// schedule simulated on `threads` threads, each task on one, and the work of the tasks that run alone
    /// in it (with faer's parallel dense kernels in the factorisation).
    pub fn figures(&self, threads: usize) -> [f64; 4] {
        let total = self.work.iter().sum();
        let critical = self.priority.iter().copied().fold(0.0, f64::max);
        let nt = self.work.len();
        let mut below = self.below.clone();
        let mut ready: Vec<usize> = (0..nt).filter(|&t| below[t] == 0).collect();
        // (finish time, task) of the tasks running
        let mut running: Vec<(f64, usize)> = Vec::new();
        let (mut now, mut alone) = (0.0f64, 0.0);
        loop {
            while running.len() < threads && !ready.is_empty() {
                let i = (0..ready.len()).max_by(|&i, &j| self.priority[ready[i]].total_cmp(&self.priority[ready[j]]));
                let t = ready.swap_remove(i.unwrap_or(0));
                if running.is_empty() && ready.is_empty() {
                    alone += self.work[t];
                }
                running.push((now + self.work[t], t));
            }
            let Some(i) = (0..running.len()).min_by(|&i, &j| running[i].0.total_cmp(&running[j].0)) else { break };
            let (end, t) = running.swap_remove(i);
            now = end;
            for &u in &self.next[t] {
                below[u] -= 1;
                if below[u] == 0 {
                    ready.push(u);
                }
            }
        }
        [total, critical, now, alone]
    }
}

/// The cut of `tree` (supernodes of work `own`) for `threads` threads: the head of each supernode's task,
/// and whether it is taken off. A subtree is split (its root taken off, its children's subtrees cut
/// again) while it holds more than 1/(GRAIN · threads) of the work and its root has children; a root
/// taken off is its own head, the supernodes of a subtree not split have its root as head. Parents are
/// numbered after their children, so a walk down the numbers meets a parent's cut before its children.
fn cut(tree: &Tree, own: &[f64], threads: usize) -> (Vec<u32>, Vec<bool>) {
    let ns = own.len();
    let mut sub = own.to_vec();
    let mut has_child = vec![false; ns];
    for s in 0..ns {
        if tree.parent[s] != NONE {
            sub[tree.parent[s]] += sub[s];
            has_child[tree.parent[s]] = true;
        }
    }
    let limit = own.iter().sum::<f64>() / (GRAIN * threads as f64);
    let (mut head, mut split) = (vec![0u32; ns], vec![false; ns]);
    for s in (0..ns).rev() {
        let p = tree.parent[s];
        if p == NONE || split[p] {
            head[s] = s as u32;
            split[s] = sub[s] > limit && has_child[s];
        } else {
            head[s] = head[p];
        }
    }
    (head, split)
}
